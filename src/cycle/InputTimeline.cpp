#include "projection_collision_avoidance/cycle/InputTimeline.hpp"

#include <algorithm>
#include <utility>

namespace projection_collision_avoidance {

InputTimeline::InputTimeline(std::string topic, const InputTimelineOptions& options,
                             InputGuard::Clock::time_point (*clock)())
    : guard_(std::move(topic), options.limits, clock),
      correction_(options.correction),
      watch_time_(options.watch_time) {}

InputTimeline::InputTimeline(InputTimeline&& other) noexcept { *this = std::move(other); }

InputTimeline& InputTimeline::operator=(InputTimeline&& other) noexcept {
  guard_ = std::move(other.guard_);
  correction_ = other.correction_;
  jumps_ = other.jumps_;
  watch_time_ = other.watch_time_;
  raw_ns_ = other.raw_ns_;
  now_ns_ = other.now_ns_;
  offset_ns_ = other.offset_ns_;
  stamp_ns_.store(other.stamp_ns_.load());
  receipt_ns_.store(other.receipt_ns_.load());
  rejected_.store(other.rejected_.load());
  superseded_.store(other.superseded_.load());
  skew_.store(other.skew_.load());
  return *this;
}

bool InputTimeline::noteTime(std::int64_t now_ns) {
  if (!jumps_.wentBack(now_ns)) {
    return false;
  }
  restart();
  return true;
}

bool InputTimeline::checkHeader(const std::string& frame_id, std::int64_t stamp_ns,
                                std::int64_t now_ns) {
  if (watch_time_) {
    noteTime(now_ns);
  }
  raw_ns_ = stamp_ns;
  now_ns_ = now_ns;
  // Judged on the sender's clock: its order on the raw stamps, its age against the receiver's
  // time moved back by the offset.
  offset_ns_ = correction_.offsetFor(stamp_ns, now_ns);
  const bool admitted = guard_.checkHeader(frame_id, stamp_ns, now_ns - offset_ns_);
  rejected_.store(guard_.rejected(), std::memory_order_relaxed);
  superseded_.store(guard_.superseded(), std::memory_order_relaxed);
  return admitted;
}

void InputTimeline::checkReceipt(std::int64_t now_ns) {
  if (watch_time_) {
    noteTime(now_ns);
  }
  raw_ns_ = now_ns;
  now_ns_ = now_ns;
  offset_ns_ = 0;
}

void InputTimeline::reject(Rejection kind, const std::string& detail) {
  guard_.reject(kind, detail);
  rejected_.store(guard_.rejected(), std::memory_order_relaxed);
}

std::int64_t InputTimeline::accept() {
  const std::int64_t corrected = raw_ns_ + offset_ns_;
  // On the receiver's clock, never before the one before (the estimate's offset may shrink).
  const std::int64_t stamp =
      guard_.haveAccepted() ? std::max(corrected, stamp_ns_.load(std::memory_order_relaxed) + 1)
                            : corrected;
  guard_.accept(raw_ns_, now_ns_ - offset_ns_);
  correction_.accepted(raw_ns_, now_ns_);
  skew_.store(correction_.lastSkew(), std::memory_order_relaxed);
  stamp_ns_.store(stamp, std::memory_order_relaxed);
  receipt_ns_.store(now_ns_, std::memory_order_release);
  return stamp;
}

void InputTimeline::restart() {
  guard_.restartTimeline();
  correction_.reset();
  receipt_ns_.store(kNone, std::memory_order_release);
}

double InputTimeline::age(std::int64_t now_ns) const {
  const std::int64_t receipt = receipt_ns_.load(std::memory_order_acquire);
  if (receipt == kNone || receipt > now_ns) {
    return kNoInputAge;
  }
  return inputAge(now_ns, stamp_ns_.load(std::memory_order_relaxed), receipt);
}

}  // namespace projection_collision_avoidance
