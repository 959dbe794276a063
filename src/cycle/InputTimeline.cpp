#include "projection_collision_avoidance/cycle/InputTimeline.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <utility>

namespace projection_collision_avoidance {
namespace {

constexpr double kNanosecondsPerSecond = 1e9;
constexpr double kMaxTimeout = 1e6;  // s, as StampCorrection's window and offset

/// The refusal of a message of @p publisher while @p holder holds the input.
std::string foreignReason(std::string_view publisher, const std::string& holder) {
  return "from '" + boundedText(std::string(publisher), InputGuard::kMaxQuotedLength) +
         "' while '" + boundedText(holder, InputGuard::kMaxQuotedLength) + "' holds the input";
}

}  // namespace

InputTimeline::InputTimeline(std::string topic, const InputTimelineOptions& options,
                             InputGuard::Clock::time_point (*clock)())
    : guard_(std::move(topic), options.limits, clock),
      correction_(options.correction),
      watch_time_(options.watch_time) {
  if (!(options.timeout >= 0.0) || !(options.timeout <= kMaxTimeout)) {
    throw std::invalid_argument("timeout must lie in [0, 1e6] s, got " +
                                std::to_string(options.timeout));
  }
  double timeout = options.timeout;
  if (!(timeout > 0.0)) {
    timeout = options.limits.max_age > 0.0 && options.limits.max_age <= kMaxTimeout
                  ? options.limits.max_age
                  : 1.0;
  }
  timeout_ns_ = std::llround(timeout * kNanosecondsPerSecond);
  if (options.correction.policy != ClockPolicy::kStamps) {
    check_plausible_ = true;
    max_offset_ns_ = std::llround(options.correction.max_offset * kNanosecondsPerSecond);
  }
  holder_.reserve(kHolderCapacity);
}

InputTimeline::InputTimeline(InputTimeline&& other) noexcept { *this = std::move(other); }

InputTimeline& InputTimeline::operator=(InputTimeline&& other) noexcept {
  guard_ = std::move(other.guard_);
  correction_ = other.correction_;
  jumps_ = other.jumps_;
  watch_time_ = other.watch_time_;
  timeout_ns_ = other.timeout_ns_;
  check_plausible_ = other.check_plausible_;
  max_offset_ns_ = other.max_offset_ns_;
  holder_ = std::move(other.holder_);
  holder_heard_ns_ = other.holder_heard_ns_;
  renew_holder_ = other.renew_holder_;
  quiet_since_ns_ = other.quiet_since_ns_;
  refused_since_ = other.refused_since_;
  raw_ns_ = other.raw_ns_;
  now_ns_ = other.now_ns_;
  offset_ns_ = other.offset_ns_;
  stamp_ns_.store(other.stamp_ns_.load());
  receipt_ns_.store(other.receipt_ns_.load());
  rejected_.store(other.rejected_.load());
  superseded_.store(other.superseded_.load());
  skew_.store(other.skew_.load());
  foreign_.store(other.foreign_.load());
  foreign_heard_ns_.store(other.foreign_heard_ns_.load());
  handovers_.store(other.handovers_.load());
  restarts_.store(other.restarts_.load());
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
                                std::int64_t now_ns, std::string_view publisher) {
  if (watch_time_) {
    noteTime(now_ns);
  }
  raw_ns_ = stamp_ns;
  now_ns_ = now_ns;
  offset_ns_ = 0;
  const bool admitted = judgeHeader(frame_id, stamp_ns, now_ns, publisher);
  rejected_.store(guard_.rejected(), std::memory_order_relaxed);
  superseded_.store(guard_.superseded(), std::memory_order_relaxed);
  return admitted;
}

bool InputTimeline::judgeHeader(const std::string& frame_id, std::int64_t stamp_ns,
                                std::int64_t now_ns, std::string_view publisher) {
  if (!admitPublisher(publisher, now_ns)) {
    guard_.reject(Rejection::kPublisher, foreignReason(publisher, holder_));
    return false;
  }
  if (refused_since_ && guard_.haveAccepted() && now_ns - quiet_since_ns_ > timeout_ns_) {
    startAfresh(now_ns);  // locked out for the timeout: the order and offset start again
    restarts_.fetch_add(1, std::memory_order_relaxed);
  }
  // Both are in [0, 2^32 s): the difference fits an int64.
  const std::int64_t skew = now_ns - stamp_ns;
  if (check_plausible_ && stamp_ns != 0 && (skew > max_offset_ns_ || skew < -max_offset_ns_)) {
    std::ostringstream why;
    why << "stamped " << -1e-9 * static_cast<double>(skew)
        << " s from the clock, beyond ~clock_skew/max_offset";
    guard_.reject(Rejection::kImplausible, why.str());
    return false;
  }
  // Judged on the sender's clock: its order on the raw stamps, its age against the receiver's
  // time moved back by the offset.
  offset_ns_ = correction_.offsetFor(stamp_ns, now_ns);
  if (guard_.checkHeader(frame_id, stamp_ns, now_ns - offset_ns_)) {
    return true;
  }
  switch (guard_.lastSuperseded() ? Rejection::kOutOfOrder : guard_.lastKind()) {
    case Rejection::kFuture:
    case Rejection::kStale:
    case Rejection::kOutOfOrder:
    case Rejection::kRepeated:
      refused_since_ = true;  // refusals the timeline's own state may cause
      break;
    default:
      break;
  }
  return false;
}

bool InputTimeline::admitPublisher(std::string_view publisher, std::int64_t now_ns) {
  if (publisher.empty()) {
    return true;
  }
  if (renew_holder_) {  // the clock went back: the holder's last word is dated now
    holder_heard_ns_ = now_ns;
    renew_holder_ = false;
  }
  if (holder_.empty() || publisher == holder_) {
    if (holder_.empty()) {
      holder_.assign(publisher);
    }
    holder_heard_ns_ = now_ns;
    return true;
  }
  if (now_ns - holder_heard_ns_ > timeout_ns_) {  // the holder went quiet: the input passes on
    holder_.assign(publisher);
    holder_heard_ns_ = now_ns;
    handovers_.fetch_add(1, std::memory_order_relaxed);
    startAfresh(now_ns);
    return true;
  }
  foreign_.fetch_add(1, std::memory_order_relaxed);
  foreign_heard_ns_.store(now_ns, std::memory_order_relaxed);
  return false;
}

void InputTimeline::startAfresh(std::int64_t now_ns) {
  guard_.restartTimeline();
  correction_.reset();
  quiet_since_ns_ = now_ns;
  refused_since_ = false;
}

bool InputTimeline::checkReceipt(std::int64_t now_ns, std::string_view publisher) {
  if (watch_time_) {
    noteTime(now_ns);
  }
  raw_ns_ = now_ns;
  now_ns_ = now_ns;
  offset_ns_ = 0;
  if (!admitPublisher(publisher, now_ns)) {
    guard_.reject(Rejection::kPublisher, foreignReason(publisher, holder_));
    rejected_.store(guard_.rejected(), std::memory_order_relaxed);
    return false;
  }
  return true;
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
  correction_.accepted(raw_ns_, now_ns_, offset_ns_);
  quiet_since_ns_ = now_ns_;
  refused_since_ = false;
  skew_.store(correction_.lastSkew(), std::memory_order_relaxed);
  stamp_ns_.store(stamp, std::memory_order_relaxed);
  receipt_ns_.store(now_ns_, std::memory_order_release);
  return stamp;
}

void InputTimeline::restart() {
  guard_.restartTimeline();
  correction_.reset();
  refused_since_ = false;
  renew_holder_ = true;
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
