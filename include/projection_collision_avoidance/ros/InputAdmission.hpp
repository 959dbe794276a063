#pragma once

#include <cstdint>
#include <exception>
#include <string>
#include <string_view>

#include <boost/function.hpp>
#include <ros/callback_queue_interface.h>
#include <ros/console.h>
#include <ros/message_event.h>
#include <ros/node_handle.h>
#include <ros/subscribe_options.h>
#include <ros/time.h>
#include <ros/transport_hints.h>
#include <std_msgs/Header.h>

#include "projection_collision_avoidance/cycle/InputGuard.hpp"
#include "projection_collision_avoidance/cycle/InputTimeline.hpp"
#include "projection_collision_avoidance/cycle/TimeJumpWatch.hpp"

namespace projection_collision_avoidance {

/// @p time in ns since the epoch; exact over the whole range of ros::Time.
inline std::int64_t nanosecondsOf(const ros::Time& time) {
  return static_cast<std::int64_t>(time.toNSec());
}

/// The ros::Time of @p ns since the epoch (0 for a negative value).
inline ros::Time rosTimeOf(std::int64_t ns) {
  ros::Time time;
  time.fromNSec(static_cast<std::uint64_t>(ns < 0 ? 0 : ns));
  return time;
}

/// later - earlier (s), without the range exception of ros::Duration.
inline double secondsBetween(const ros::Time& later, const ros::Time& earlier) {
  return 1e-9 * static_cast<double>(nanosecondsOf(later) - nanosecondsOf(earlier));
}

/// InputGuard::checkHeader for a ROS header at ROS time @p now.
inline bool checkHeader(InputGuard& guard, const std_msgs::Header& header, const ros::Time& now) {
  return guard.checkHeader(header.frame_id, nanosecondsOf(header.stamp), nanosecondsOf(now));
}

/// Logs (WARN, prefixed with @p node) the line @p admission (an InputGuard or an InputTimeline)
/// asks for, if any.
template <typename Admission>
void logRejection(Admission& admission, const std::string& node) {
  const std::string line = admission.takeLogLine();
  if (!line.empty()) {
    ROS_WARN_STREAM(node << ": " << line);
  }
}

/// Runs @p judge (the checks and the use of one input message) so that nothing it throws
/// leaves the callback: a message that cannot be judged is refused as kUnjudgeable and counted
/// by @p admission (an InputGuard or an InputTimeline). Then logs what it asks for.
template <typename Admission, typename Judge>
void admitGuarded(Admission& admission, const std::string& node, Judge&& judge) noexcept {
  try {
    try {
      judge();
    } catch (const std::exception& error) {
      admission.reject(Rejection::kUnjudgeable, error.what());
    } catch (...) {
      admission.reject(Rejection::kUnjudgeable, "unknown exception");
    }
    logRejection(admission, node);
  } catch (...) {  // out of memory while counting: drop the message, keep the node
  }
}

/// InputTimeline::checkHeader() for a ROS header received at ROS time @p now (a jump back of
/// ROS time restarts the timeline, the stamp is put on this clock, the header judged).
/// @p publisher: the sender's caller id (publisherOf()), "" for a message handed over within the
/// node (no one-publisher rule).
inline bool checkHeader(InputTimeline& timeline, const std_msgs::Header& header,
                        const ros::Time& now, std::string_view publisher = {}) {
  return timeline.checkHeader(header.frame_id, nanosecondsOf(header.stamp), nanosecondsOf(now),
                              publisher);
}

/// The caller id of the node that published @p event's message, as roscpp's connection header
/// gives it (nodelets of one manager share the manager's).
template <typename Message>
const std::string& publisherOf(const ros::MessageEvent<Message const>& event) {
  return event.getPublisherName();
}

/// Subscribes @p topic (TCP_NODELAY unless @p hints say otherwise; on @p queue when given) with
/// @p callback, which gets each message's ros::MessageEvent, so that its publisher is known
/// (publisherOf()).
template <typename Message, typename Callback>
ros::Subscriber subscribeEvents(
    ros::NodeHandle& nh, const std::string& topic, std::uint32_t queue_size, Callback&& callback,
    const ros::TransportHints& hints = ros::TransportHints().tcpNoDelay(),
    ros::CallbackQueueInterface* queue = nullptr) {
  using Event = const ros::MessageEvent<Message const>&;
  ros::SubscribeOptions options;
  options.template initByFullCallbackType<Event>(
      topic, queue_size, boost::function<void(Event)>(std::forward<Callback>(callback)));
  options.transport_hints = hints;
  if (queue != nullptr) {
    options.callback_queue = queue;
  }
  return nh.subscribe(options);
}

/// TimeJumpWatch::wentBack() at ROS time @p now.
inline bool wentBack(TimeJumpWatch& watch, const ros::Time& now) {
  return watch.wentBack(nanosecondsOf(now));
}

}  // namespace projection_collision_avoidance
