#include "projection_collision_avoidance/vehicle/VehicleResponseEstimator.hpp"

#include <cmath>
#include <string>

#include "projection_collision_avoidance/core/ParameterError.hpp"

namespace projection_collision_avoidance {
namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();
/// Segments that asked for an acceleration before the realised fraction is given.
constexpr int kMinExcitedSegments = 5;
/// Another delay is taken only when its error is below this fraction of the current one's.
constexpr double kSwitchRatio = 0.8;

}  // namespace

VehicleResponseEstimator::VehicleResponseEstimator(const ResponseEstimatorOptions& options)
    : options_(options) {
  if (!(options.period > 0.0) || !std::isfinite(options.period)) {
    throw ParameterError("vehicle.velocity.period",
                         "must be finite and > 0 s, got " + std::to_string(options.period));
  }
  if (!(options.max_delay >= 0.0) ||
      !(options.max_delay <= (kMaxCandidates - 1) * options.period)) {
    throw ParameterError("vehicle.velocity.max_delay",
                         "must be >= 0 s and at most 255 control periods (" +
                             std::to_string((kMaxCandidates - 1) * options.period) + " s), got " +
                             std::to_string(options.max_delay));
  }
  if (!(options.averaging_time > 0.0) || !std::isfinite(options.averaging_time)) {
    throw ParameterError("vehicle.velocity.averaging_time",
                         "must be finite and > 0 s, got " + std::to_string(options.averaging_time));
  }
  if (!(options.min_acceleration >= 0.0) || !std::isfinite(options.min_acceleration)) {
    throw ParameterError(
        "vehicle.velocity.min_acceleration",
        "must be finite and >= 0 m/s², got " + std::to_string(options.min_acceleration));
  }
  if (!(options.segment > 0.0) || !std::isfinite(options.segment)) {
    throw ParameterError("vehicle.velocity.segment",
                         "must be finite and > 0 s, got " + std::to_string(options.segment));
  }
  candidates_ = static_cast<int>(std::floor(options.max_delay / options.period + 1e-9)) + 1;
  reset();
}

void VehicleResponseEstimator::reset() {
  error_.fill(kInfinity);
  chosen_ = 0;
  previous_.resize(0);
  previous_time_ = 0.0;
  cross_ = 0.0;
  commanded_ = 0.0;
  excited_ = 0;
  segment_velocity_.resize(0);
  segment_time_ = 0.0;
  response_ = VehicleResponse();
}

void VehicleResponseEstimator::noteSegment(const AxisVector& velocity, double changed_at,
                                           const CommandHistory& history) {
  if (segment_velocity_.size() != velocity.size()) {
    segment_velocity_ = velocity;
    segment_time_ = changed_at;
    return;
  }
  const double dt = changed_at - segment_time_;
  if (dt < options_.segment) {
    return;
  }
  const double delay = response_.delay;
  const AxisVector commanded = history.incrementBetween(segment_time_ - delay, changed_at - delay);
  // Only segments whose commands asked for an acceleration: at rest or cruising, the noise of
  // Δv would make the ratio.
  if (commanded.norm() >= options_.min_acceleration * dt) {
    const double weight = -std::expm1(-dt / options_.averaging_time);
    const AxisVector realised = velocity - segment_velocity_;
    cross_ += weight * (realised.dot(commanded) - cross_);
    commanded_ += weight * (commanded.squaredNorm() - commanded_);
    ++excited_;
  }
  response_.realised_fraction = excited_ >= kMinExcitedSegments && commanded_ > 0.0
                                    ? cross_ / commanded_
                                    : std::numeric_limits<double>::quiet_NaN();
  segment_velocity_ = velocity;
  segment_time_ = changed_at;
}

void VehicleResponseEstimator::observe(const AxisVector& velocity, double changed_at,
                                       const CommandHistory& history) {
  if (velocity.size() != history.axes() || !velocity.allFinite() || !std::isfinite(changed_at)) {
    return;
  }
  const bool have_previous = previous_.size() == velocity.size();
  if (have_previous && !(changed_at > previous_time_)) {
    reset();  // time went back, or the same change twice
  }
  double weight = 1.0;
  if (previous_.size() == velocity.size()) {
    const double dt = changed_at - previous_time_;
    weight = -std::expm1(-dt / options_.averaging_time);
    response_.update_interval =
        std::isnan(response_.update_interval)
            ? dt
            : response_.update_interval + 0.1 * (dt - response_.update_interval);
  }
  // Candidates in order of growing delay meet the history from its newest command backwards.
  std::size_t index = 0;
  for (int j = 0; j < candidates_; ++j) {
    const double at = changed_at - j * options_.period;
    while (index < history.size() && history.fromNewest(index).time >= at) {
      ++index;
    }
    if (index == history.size()) {
      break;  // no command in force that early
    }
    const double e = (velocity - history.fromNewest(index).velocity).squaredNorm();
    error_[j] = std::isinf(error_[j]) ? e : error_[j] + weight * (e - error_[j]);
  }
  int best = chosen_;
  for (int j = 0; j < candidates_; ++j) {
    if (error_[j] < error_[best]) {
      best = j;
    }
  }
  if (std::isinf(error_[chosen_]) || error_[best] < kSwitchRatio * error_[chosen_]) {
    chosen_ = best;
  }
  response_.delay = chosen_ * options_.period;
  noteSegment(velocity, changed_at, history);
  previous_ = velocity;
  previous_time_ = changed_at;
  ++response_.observations;
}

}  // namespace projection_collision_avoidance
