#include "projection_collision_avoidance/cycle/StepPacer.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace projection_collision_avoidance {

StepPacer::StepPacer(double period) {
  // 1e9 s at most: the credit's arithmetic stays far inside 64 bits.
  if (!(period > 0.0) || !(period <= 1e9)) {
    throw std::invalid_argument("StepPacer: the period must be > 0 s and finite");
  }
  period_ns_ = std::max<std::int64_t>(1, static_cast<std::int64_t>(std::ceil(period * 1e9)));
}

bool StepPacer::admit(std::int64_t stamp_ns) {
  if (!started_) {
    started_ = true;
    credit_ns_ = period_ns_;
  } else if (stamp_ns > last_stamp_ns_) {
    // Accrued credit is capped at one period, so an elapsed time beyond it adds nothing more
    // (and cannot overflow: stamp_ns - last_stamp_ns_ is computed unsigned).
    const auto elapsed =
        static_cast<std::uint64_t>(stamp_ns) - static_cast<std::uint64_t>(last_stamp_ns_);
    const auto room = static_cast<std::uint64_t>(period_ns_ - credit_ns_);
    credit_ns_ += static_cast<std::int64_t>(std::min(elapsed, room));
  }
  last_stamp_ns_ = stamp_ns;
  if (2 * credit_ns_ < period_ns_) {
    return false;
  }
  credit_ns_ -= period_ns_;
  return true;
}

}  // namespace projection_collision_avoidance
