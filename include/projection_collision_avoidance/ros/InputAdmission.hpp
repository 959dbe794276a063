#pragma once

#include <cstdint>
#include <exception>
#include <string>

#include <ros/console.h>
#include <ros/time.h>
#include <std_msgs/Header.h>

#include "projection_collision_avoidance/ros/InputGuard.hpp"

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

/// Logs (WARN, prefixed with @p node) the line @p guard asks for, if any.
inline void logRejection(InputGuard& guard, const std::string& node) {
  const std::string line = guard.takeLogLine();
  if (!line.empty()) {
    ROS_WARN_STREAM(node << ": " << line);
  }
}

/// Runs @p judge (the checks and the use of one input message) so that nothing it throws
/// leaves the callback: a message that cannot be judged is refused as kUnjudgeable and counted.
/// Then logs what the guard asks for.
template <typename Judge>
void admitGuarded(InputGuard& guard, const std::string& node, Judge&& judge) noexcept {
  try {
    try {
      judge();
    } catch (const std::exception& error) {
      guard.reject(Rejection::kUnjudgeable, error.what());
    } catch (...) {
      guard.reject(Rejection::kUnjudgeable, "unknown exception");
    }
    logRejection(guard, node);
  } catch (...) {  // out of memory while counting: drop the message, keep the node
  }
}

/// Watches ROS time for jumps back (a restarted simulator's /clock, a looping bag, an NTP step
/// on wall time): wentBack() is true once per jump, the first time a time earlier than the
/// latest one seen is passed.
class ClockWatch {
 public:
  /// Records @p now; true when it lies before the latest time seen (the jump's size: jump()).
  bool wentBack(const ros::Time& now) {
    const std::int64_t now_ns = nanosecondsOf(now);
    const bool back = have_latest_ && now_ns < latest_ns_;
    jump_ = back ? 1e-9 * static_cast<double>(now_ns - latest_ns_) : 0.0;
    latest_ns_ = now_ns;
    have_latest_ = true;
    if (back) {
      ++jumps_;
    }
    return back;
  }
  /// Size (s, negative) of the last jump back reported by wentBack().
  double jump() const { return jump_; }
  /// Jumps back seen since start.
  std::uint32_t jumps() const { return jumps_; }

 private:
  bool have_latest_ = false;
  std::int64_t latest_ns_ = 0;
  double jump_ = 0.0;
  std::uint32_t jumps_ = 0;
};

/// Notes a jump back of ROS time at @p now on @p clock (restarting @p guard's timeline), then
/// judges @p header (checkHeader()).
inline bool checkHeaderOnTimeline(InputGuard& guard, ClockWatch& clock,
                                  const std_msgs::Header& header, const ros::Time& now) {
  if (clock.wentBack(now)) {
    guard.restartTimeline();
  }
  return checkHeader(guard, header, now);
}

}  // namespace projection_collision_avoidance
