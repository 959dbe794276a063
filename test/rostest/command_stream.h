#pragma once

/// @file
/// Velocity commands sent at a steady wall rate from a queue and thread of their own (the
/// rostests of the plant's vehicles).

#include <mutex>
#include <string>

#include <geometry_msgs/Twist.h>
#include <geometry_msgs/TwistStamped.h>
#include <ros/callback_queue.h>
#include <ros/ros.h>

namespace projection_collision_avoidance {
namespace testing {

/// Publishes a Twist (or TwistStamped) at a steady wall rate from a queue and thread of its own
/// while it is set.
class CommandStream {
 public:
  CommandStream(const std::string& topic, bool stamped, double rate) : stamped_(stamped) {
    nh_.setCallbackQueue(&queue_);
    publisher_ = stamped ? nh_.advertise<geometry_msgs::TwistStamped>(topic, 10)
                         : nh_.advertise<geometry_msgs::Twist>(topic, 10);
    timer_ = nh_.createWallTimer(ros::WallDuration(1.0 / rate),
                                 [this](const ros::WallTimerEvent& /*event*/) { publish(); });
    spinner_.start();
  }
  ~CommandStream() {
    timer_.stop();
    spinner_.stop();
  }
  CommandStream(const CommandStream&) = delete;
  CommandStream& operator=(const CommandStream&) = delete;

  void set(const geometry_msgs::Twist& twist) {
    const std::lock_guard<std::mutex> lock(mutex_);
    twist_ = twist;
    active_ = true;
  }
  /// Stops sending; returns the ROS time of the last message sent.
  ros::Time stop() {
    const std::lock_guard<std::mutex> lock(mutex_);
    active_ = false;
    return last_sent_;
  }
  bool heard() const { return publisher_.getNumSubscribers() > 0; }
  /// Sends @p twist once, now (from the caller's thread).
  void sendOnce(const geometry_msgs::Twist& twist) { send(twist); }

 private:
  void publish() {
    const std::lock_guard<std::mutex> lock(mutex_);
    if (active_) {
      send(twist_);
      last_sent_ = ros::Time::now();
    }
  }
  void send(const geometry_msgs::Twist& twist) {
    if (stamped_) {
      geometry_msgs::TwistStamped msg;
      msg.header.stamp = ros::Time::now();
      msg.twist = twist;
      publisher_.publish(msg);
    } else {
      publisher_.publish(twist);
    }
  }

  bool stamped_;
  std::mutex mutex_;
  geometry_msgs::Twist twist_;
  bool active_ = false;
  ros::Time last_sent_;
  ros::CallbackQueue queue_;
  ros::NodeHandle nh_;
  ros::Publisher publisher_;
  ros::WallTimer timer_;
  ros::AsyncSpinner spinner_{1, &queue_};
};

inline geometry_msgs::Twist twistOf(double vx, double vy, double vz, double wx, double wy,
                                    double wz) {
  geometry_msgs::Twist t;
  t.linear.x = vx;
  t.linear.y = vy;
  t.linear.z = vz;
  t.angular.x = wx;
  t.angular.y = wy;
  t.angular.z = wz;
  return t;
}

}  // namespace testing
}  // namespace projection_collision_avoidance
