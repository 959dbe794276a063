#pragma once

#include <atomic>
#include <cstdint>

namespace projection_collision_avoidance {

/// The follower cycle's wait after a stall, free of ROS: a tick more than half the measurement
/// timeout late on ROS time, or that long after the tick before on the steady clock, starts a
/// wait in which ticks are skipped until a measurement is accepted, or half the timeout has passed
/// on the steady clock since the wait began (late on ROS time only) or since the latest
/// measurement refused as stamped ahead of this clock (noteFutureMeasurement()), but at most
/// max(measurement timeout, the stall) in all. Simulated time can catch up by seconds within a
/// millisecond when a stalled process resumes, before the measurements sent meanwhile are read,
/// or replay the stall period by period, refusing the newest measurements as future until it has
/// caught up. Allocates nothing.
class StallWait {
 public:
  /// @param measurement_timeout s after which a measurement is stale (> 0)
  /// @param period the control period T (s)
  StallWait(double measurement_timeout, double period)
      : timeout_(measurement_timeout), grace_(0.5 * measurement_timeout), period_(period) {}

  /// The input side refused a measurement stamped ahead of this process's clock (any thread,
  /// lock-free).
  void noteFutureMeasurement() { future_measurements_.fetch_add(1, std::memory_order_relaxed); }

  /// At a tick at steady time @p steady_ns, @p delay s after it was due on ROS time, with the
  /// latest measurement's sequence number @p sequence: true while the tick must wait (skip).
  bool holds(std::int64_t steady_ns, double delay, std::uint64_t sequence);

  /// The stall (s) this tick detected, 0 when none.
  double stall() const { return stall_; }

 private:
  double timeout_;
  double grace_;  ///< half the measurement timeout (s)
  double period_;
  bool resuming_ = false;                  ///< waiting for input after a stall
  std::int64_t resumed_at_steady_ns_ = 0;  ///< the wait's start, or the latest future refusal
  std::int64_t stall_began_steady_ns_ = 0;
  double wait_limit_ = 0.0;  ///< s of steady time the wait may last in all
  std::uint64_t sequence_at_stall_ = 0;
  std::atomic<std::uint64_t> future_measurements_{0};  ///< noteFutureMeasurement() calls
  std::uint64_t future_seen_ = 0;                      ///< the count at the tick before
  bool have_future_ = false;
  std::int64_t last_future_steady_ns_ = 0;  ///< the tick that saw the latest future refusal
  bool wait_anchored_ = false;  ///< the wait has a start: late on ROS time, or a future refusal
  bool have_last_tick_steady_ = false;
  std::int64_t last_tick_steady_ns_ = 0;
  double stall_ = 0.0;
};

}  // namespace projection_collision_avoidance
