#include "projection_collision_avoidance/cycle/StampCorrection.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace projection_collision_avoidance {
namespace {

constexpr double kNanosecondsPerSecond = 1e9;
constexpr double kMaxSeconds = 1e6;  // about 11 days: far beyond any window or offset
/// 2^60 ns (36 years): |offsets| stay below it (skews of stamps in ros::Time's range are below
/// 2^62), so the clamp's ends cannot overflow.
constexpr std::int64_t kMaxNs = std::int64_t{1} << 60;

std::int64_t floorDiv(std::int64_t a, std::int64_t b) {
  const std::int64_t q = a / b;
  return (a % b != 0 && ((a < 0) != (b < 0))) ? q - 1 : q;
}

}  // namespace

const char* toString(ClockPolicy policy) {
  switch (policy) {
    case ClockPolicy::kReceipt:
      return "receipt";
    case ClockPolicy::kEstimate:
      return "estimate";
    case ClockPolicy::kStamps:
    default:
      return "stamps";
  }
}

StampCorrection::StampCorrection(const StampCorrectionOptions& options) : options_(options) {
  if (!(options.window > 0.0) || !(options.window <= kMaxSeconds)) {
    throw std::invalid_argument("window must lie in (0, 1e6] s, got " +
                                std::to_string(options.window));
  }
  if (!(options.max_offset >= 0.0) || !(options.max_offset <= kMaxSeconds)) {
    throw std::invalid_argument("max_offset must lie in [0, 1e6] s, got " +
                                std::to_string(options.max_offset));
  }
  if (!(options.max_drift_rate >= 0.0) || !(options.max_drift_rate <= 1.0)) {
    throw std::invalid_argument("max_drift_rate must lie in [0, 1] s/s, got " +
                                std::to_string(options.max_drift_rate));
  }
  max_drift_rate_ = options.max_drift_rate;
  bucket_ns_ =
      std::max<std::int64_t>(1, std::llround(options.window * kNanosecondsPerSecond / kBuckets));
  max_offset_ns_ = std::llround(options.max_offset * kNanosecondsPerSecond);
}

bool StampCorrection::minimum(std::int64_t receipt_ns, std::int64_t* skew) const {
  const std::int64_t now = floorDiv(receipt_ns, bucket_ns_);
  bool any = false;
  for (const Bucket& b : buckets_) {
    if (b.index <= now && b.index > now - kBuckets) {
      *skew = any ? std::min(*skew, b.minimum) : b.minimum;
      any = true;
    }
  }
  return any;
}

double StampCorrection::minimumSkew(std::int64_t receipt_ns) const {
  std::int64_t skew = 0;
  return minimum(receipt_ns, &skew) ? static_cast<double>(skew) / kNanosecondsPerSecond
                                    : std::numeric_limits<double>::quiet_NaN();
}

std::int64_t StampCorrection::offsetFor(std::int64_t stamp_ns, std::int64_t receipt_ns) const {
  if (stamp_ns == 0 || options_.policy == ClockPolicy::kStamps) {
    return 0;
  }
  const std::int64_t own = receipt_ns - stamp_ns;
  if (options_.policy == ClockPolicy::kReceipt) {
    return own;
  }
  std::int64_t skew = 0;
  const std::int64_t target = minimum(receipt_ns, &skew) ? skew : own;
  if (!have_offset_) {
    return target;
  }
  // |o − o_used| <= rate × elapsed; a receipt before the last one's (not expected on one
  // timeline) allows no drift.
  const double elapsed = static_cast<double>(std::max<std::int64_t>(0, receipt_ns - offset_at_));
  const auto step = static_cast<std::int64_t>(
      std::min(max_drift_rate_ * elapsed, static_cast<double>(2 * kMaxNs)));
  return std::clamp(target, offset_ns_ - step, offset_ns_ + step);
}

void StampCorrection::accepted(std::int64_t stamp_ns, std::int64_t receipt_ns,
                               std::int64_t offset_ns) {
  accepted(stamp_ns, receipt_ns);
  if (options_.policy == ClockPolicy::kEstimate && stamp_ns != 0 && offset_ns < kMaxNs &&
      offset_ns > -kMaxNs) {
    have_offset_ = true;
    offset_ns_ = offset_ns;
    offset_at_ = receipt_ns;
  }
}

void StampCorrection::accepted(std::int64_t stamp_ns, std::int64_t receipt_ns) {
  const std::int64_t skew = receipt_ns - stamp_ns;
  last_skew_ = static_cast<double>(skew) / kNanosecondsPerSecond;
  if (skew > max_offset_ns_ || skew < -max_offset_ns_) {
    return;  // not learnt from: the estimate stays where the plausible messages put it
  }
  const std::int64_t index = floorDiv(receipt_ns, bucket_ns_);
  Bucket& b = buckets_[static_cast<std::size_t>(((index % kBuckets) + kBuckets) % kBuckets)];
  if (b.index != index) {
    b.index = index;
    b.minimum = skew;
  } else {
    b.minimum = std::min(b.minimum, skew);
  }
}

void StampCorrection::reset() {
  buckets_.fill(Bucket{});
  have_offset_ = false;
  last_skew_ = std::numeric_limits<double>::quiet_NaN();
}

}  // namespace projection_collision_avoidance
