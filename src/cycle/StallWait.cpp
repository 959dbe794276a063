#include "projection_collision_avoidance/cycle/StallWait.hpp"

#include <algorithm>

namespace projection_collision_avoidance {
namespace {

constexpr double kNanosecond = 1e-9;

}  // namespace

bool StallWait::holds(std::int64_t steady_ns, double delay, std::uint64_t sequence) {
  stall_ = 0.0;
  // A stall: the tick ran late by a good part of the timeout on ROS time (delay), or the process
  // did not tick for that long on the steady clock (a simulated clock replayed after a stall
  // passes its periods one by one, so that each tick looks on time).
  const double gap =
      have_last_tick_steady_
          ? kNanosecond * static_cast<double>(steady_ns - last_tick_steady_ns_) - period_
          : 0.0;
  last_tick_steady_ns_ = steady_ns;
  have_last_tick_steady_ = true;
  // Measurements refused as stamped ahead of this clock since the tick before.
  const std::uint64_t future = future_measurements_.load(std::memory_order_relaxed);
  if (future != future_seen_) {
    future_seen_ = future;
    last_future_steady_ns_ = steady_ns;
    have_future_ = true;
  }
  const double stalled = std::max(delay, gap);
  if (stalled > grace_) {
    // The measurements sent meanwhile are not read yet: wait for them. After a stall seen on the
    // steady clock alone, only while measurements are refused as future (a replaying clock; a
    // lockstep simulation that stood still with everyone else refuses none).
    resuming_ = true;
    wait_anchored_ = delay > grace_;
    resumed_at_steady_ns_ = steady_ns;
    stall_began_steady_ns_ = steady_ns;
    wait_limit_ = std::max(timeout_, stalled);
    sequence_at_stall_ = sequence;
    stall_ = stalled;
  }
  if (!resuming_) {
    return false;
  }
  // A measurement refused as future: this clock is still catching up, and the measurements will
  // be accepted once it has. Wait on from then, for at most wait_limit_ in all.
  if (have_future_ && last_future_steady_ns_ >= stall_began_steady_ns_ &&
      (!wait_anchored_ || last_future_steady_ns_ > resumed_at_steady_ns_)) {
    resumed_at_steady_ns_ = last_future_steady_ns_;
    wait_anchored_ = true;
  }
  const double quiet = kNanosecond * static_cast<double>(steady_ns - resumed_at_steady_ns_);
  const double waited = kNanosecond * static_cast<double>(steady_ns - stall_began_steady_ns_);
  if (sequence == sequence_at_stall_ && wait_anchored_ && quiet < grace_ && waited < wait_limit_) {
    return true;
  }
  resuming_ = false;
  return false;
}

}  // namespace projection_collision_avoidance
