#pragma once

#include <cstdint>

namespace projection_collision_avoidance {

/// Watches a clock (ROS time, in ns since the epoch) for jumps back: a restarted simulator's
/// /clock, a looping bag, an NTP step on wall time. wentBack() is true once per jump, the first
/// time a time earlier than the latest one seen is passed. Free of ROS; no allocation, no lock
/// (one thread at a time).
class TimeJumpWatch {
 public:
  /// Records @p now_ns (ns); true when it lies before the latest time seen (the jump's size:
  /// jump()). Standing still is no jump.
  bool wentBack(std::int64_t now_ns) {
    const bool back = have_latest_ && now_ns < latest_ns_;
    jump_ = back ? 1e-9 * static_cast<double>(now_ns - latest_ns_) : 0.0;
    latest_ns_ = now_ns;
    have_latest_ = true;
    if (back && jumps_ < UINT32_MAX) {
      ++jumps_;
    }
    return back;
  }
  /// Size (s, negative) of the jump the last wentBack() reported; 0 when it reported none.
  double jump() const { return jump_; }
  /// Jumps back seen since start (saturated).
  std::uint32_t jumps() const { return jumps_; }
  /// The latest time passed to wentBack() (ns); 0 before one.
  std::int64_t latest() const { return latest_ns_; }

 private:
  bool have_latest_ = false;
  std::int64_t latest_ns_ = 0;
  double jump_ = 0.0;
  std::uint32_t jumps_ = 0;
};

}  // namespace projection_collision_avoidance
