#pragma once

#include <atomic>
#include <cstdint>
#include <memory>
#include <string>

#include <ros/ros.h>

namespace projection_collision_avoidance {

/// A publisher that knows whether anyone subscribes without asking roscpp. Each
/// ros::Publisher::publish() and getNumSubscribers() takes roscpp's one lock over every topic of
/// the process (TopicManager) and searches the process's topics one by one: with a hundred nodelets
/// in one manager, each with a few topics, the control threads spent most of a period waiting for
/// that lock. This one counts the subscribers with the publisher's connect and disconnect
/// callbacks (run on the node handle's callback queue), so subscribed() is an atomic load and
/// publish() of a message nobody subscribes to does not reach roscpp at all.
class CountedPublisher {
 public:
  CountedPublisher() = default;

  /// Advertises @p topic on @p nh (queue @p queue_size messages) with the counting callbacks.
  template <class Message>
  void advertise(ros::NodeHandle& nh, const std::string& topic, std::uint32_t queue_size) {
    auto count = std::make_shared<std::atomic<int>>(0);  // the callbacks may outlive this object
    ros::AdvertiseOptions options;
    options.init<Message>(
        topic, queue_size,
        [count](const ros::SingleSubscriberPublisher&) {
          count->fetch_add(1, std::memory_order_relaxed);
        },
        [count](const ros::SingleSubscriberPublisher&) {
          count->fetch_sub(1, std::memory_order_relaxed);
        });
    count_ = count;
    publisher_ = nh.advertise(options);
  }

  /// Whether a subscriber is connected (as last told by its connect or disconnect callback).
  bool subscribed() const { return count_ && count_->load(std::memory_order_relaxed) > 0; }
  /// Connections to subscribers, as counted (the subscribers of one process share one).
  int subscribers() const { return count_ ? count_->load(std::memory_order_relaxed) : 0; }

  /// Publishes @p message if anyone subscribes; a shared pointer reaches a subscriber in the same
  /// process (a nodelet) as it is, neither serialised nor copied.
  template <class MessagePtr>
  void publish(const MessagePtr& message) const {
    if (subscribed()) {
      publisher_.publish(message);
    }
  }

  /// The topic as advertised (resolved).
  std::string topic() const { return publisher_.getTopic(); }
  void shutdown() { publisher_.shutdown(); }

 private:
  ros::Publisher publisher_;
  std::shared_ptr<std::atomic<int>> count_;
};

}  // namespace projection_collision_avoidance
