#include "projection_collision_avoidance/cycle/InputGuard.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <utility>

#include "projection_collision_avoidance/cycle/FrameNames.hpp"

namespace projection_collision_avoidance {
namespace {

constexpr double kNanosecond = 1e-9;

/// Seconds as whole ns, saturated to the int64 range (the limits are validated finite >= 0).
std::int64_t nanosecondsOf(double seconds) {
  const double ns = seconds * 1e9;
  if (!(ns < 9.0e18)) {
    return std::numeric_limits<std::int64_t>::max();
  }
  return static_cast<std::int64_t>(std::llround(std::max(0.0, ns)));
}

}  // namespace

const char* toString(Rejection kind) {
  switch (kind) {
    case Rejection::kFrame:
      return "frame";
    case Rejection::kZeroStamp:
      return "zero stamp";
    case Rejection::kFuture:
      return "future stamp";
    case Rejection::kStale:
      return "stale";
    case Rejection::kOutOfOrder:
      return "out of order";
    case Rejection::kRepeated:
      return "repeated stamp";
    case Rejection::kContent:
      return "content";
    case Rejection::kUnjudgeable:
      return "unjudgeable";
    case Rejection::kPublisher:
      return "other publisher";
    case Rejection::kImplausible:
      return "implausible stamp";
  }
  return "unknown";
}

std::string boundedText(const std::string& text, std::size_t length) {
  if (text.size() <= length) {
    return text;
  }
  return text.substr(0, length) + "... (" + std::to_string(text.size()) + " bytes)";
}

InputGuard::InputGuard(std::string topic, InputGuardLimits limits, Clock::time_point (*clock)())
    : topic_(std::move(topic)), limits_(std::move(limits)), clock_(clock) {}

bool InputGuard::checkHeader(const std::string& frame_id, std::int64_t stamp_ns,
                             std::int64_t now_ns) {
  last_superseded_ = false;
  if (!limits_.required_frame.empty() && !sameFrame(frame_id, limits_.required_frame)) {
    reject(Rejection::kFrame, "frame_id '" + boundedText(frame_id, kMaxQuotedLength) +
                                  "', expected '" + limits_.required_frame + "'");
    return false;
  }
  if (stamp_ns == 0) {
    reject(Rejection::kZeroStamp, "stamp 0 (unset)");
    return false;
  }
  // Both are in [0, 2^32 s), so their difference fits an int64.
  const std::int64_t ahead_ns = stamp_ns - now_ns;
  if (ahead_ns > nanosecondsOf(limits_.max_future_stamp)) {
    std::ostringstream why;
    why << "stamped " << kNanosecond * static_cast<double>(ahead_ns) << " s ahead of the clock";
    reject(Rejection::kFuture, why.str());
    return false;
  }
  if (limits_.max_age > 0.0 && -ahead_ns > nanosecondsOf(limits_.max_age)) {
    std::ostringstream why;
    why << "stamped " << kNanosecond * static_cast<double>(-ahead_ns) << " s ago, older than "
        << limits_.max_age << " s";
    reject(Rejection::kStale, why.str());
    return false;
  }
  if (have_accepted_ && stamp_ns <= last_stamp_ns_ && limits_.supersede_older) {
    supersede();
    return false;
  }
  if (have_accepted_ && stamp_ns < last_stamp_ns_) {
    reject(Rejection::kOutOfOrder, "stamped before the last accepted message");
    return false;
  }
  if (have_accepted_ && stamp_ns == last_stamp_ns_) {
    reject(Rejection::kRepeated, "stamped as the last accepted message");
    return false;
  }
  return true;
}

void InputGuard::reject(Rejection kind, const std::string& detail) {
  ++rejected_;
  ++unlogged_;
  run_length_ = kind == kind_ && run_length_ > 0 ? run_length_ + 1 : 1;
  kind_ = kind;
  last_rejection_ = std::string(toString(kind)) + ": " + boundedText(detail, kMaxReasonLength);
  const Clock::time_point now = clock_();
  const bool transition = !have_logged_ || kind != logged_kind_;
  const Clock::duration since = now - last_log_;
  if ((transition && (!have_logged_ || since >= kTransitionPeriod)) || since >= kSummaryPeriod) {
    std::ostringstream line;
    line << topic_ << " rejected: " << last_rejection_ << " (" << unlogged_
         << (unlogged_ == 1 ? " refusal" : " refusals") << " since the last line, " << rejected_
         << " in all)";
    log_line_ = line.str();
    have_logged_ = true;
    logged_kind_ = kind;
    last_log_ = now;
    unlogged_ = 0;
  }
}

void InputGuard::supersede() {
  ++superseded_;
  ++unlogged_superseded_;
  last_superseded_ = true;
  const Clock::time_point now = clock_();
  if (have_logged_superseded_ && now - last_superseded_log_ < kSummaryPeriod) {
    return;
  }
  std::ostringstream line;
  line << topic_ << ": " << unlogged_superseded_
       << (unlogged_superseded_ == 1 ? " message" : " messages")
       << " stamped at or before the latest accepted one dropped as superseded (not refused; "
       << superseded_ << " in all)";
  log_line_ = line.str();
  have_logged_superseded_ = true;
  last_superseded_log_ = now;
  unlogged_superseded_ = 0;
}

void InputGuard::accept(std::int64_t stamp_ns, std::int64_t now_ns) {
  have_accepted_ = true;
  ever_accepted_ = true;
  ++accepted_;
  last_stamp_ns_ = stamp_ns;
  effective_stamp_ns_ = std::min(stamp_ns, now_ns);
  last_rejection_.clear();
}

void InputGuard::restartTimeline() {
  have_accepted_ = false;
  last_stamp_ns_ = 0;
  effective_stamp_ns_ = 0;
}

double InputGuard::ageAt(std::int64_t now_ns) const {
  if (!have_accepted_) {
    return std::numeric_limits<double>::infinity();
  }
  return kNanosecond * static_cast<double>(now_ns - effective_stamp_ns_);
}

std::string InputGuard::takeLogLine() {
  std::string line;
  line.swap(log_line_);
  return line;
}

}  // namespace projection_collision_avoidance
