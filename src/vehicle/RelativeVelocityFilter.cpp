#include "projection_collision_avoidance/vehicle/RelativeVelocityFilter.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

namespace projection_collision_avoidance {

const char* toString(VelocityFilterVerdict verdict) {
  switch (verdict) {
    case VelocityFilterVerdict::kEstimated:
      return "estimated";
    case VelocityFilterVerdict::kStarted:
      return "started";
    case VelocityFilterVerdict::kNotIncreasing:
      return "stamp not increasing";
    case VelocityFilterVerdict::kRefused:
    default:
      return "refused";
  }
}

RelativeVelocityFilter::RelativeVelocityFilter(const VelocityFilterOptions& options)
    : options_(options) {
  if (options.axes < 1 || options.axes > 3) {
    throw std::invalid_argument("axes must be 1, 2 or 3, got " + std::to_string(options.axes));
  }
  if (!(options.bandwidth > 0.0) || !std::isfinite(options.bandwidth)) {
    throw std::invalid_argument("bandwidth must be finite and > 0 rad/s, got " +
                                std::to_string(options.bandwidth));
  }
  if (!(options.max_gap > 0.0) || !std::isfinite(options.max_gap)) {
    throw std::invalid_argument("max_gap must be finite and > 0 s, got " +
                                std::to_string(options.max_gap));
  }
}

VelocityFilterVerdict RelativeVelocityFilter::update(double t, const Eigen::Vector3d& position,
                                                     Eigen::VectorXd* state) {
  const int k = options_.axes;
  if (!std::isfinite(t) || !position.head(k).allFinite()) {
    return VelocityFilterVerdict::kRefused;
  }
  Eigen::Vector3d p = Eigen::Vector3d::Zero();
  p.head(k) = position.head(k);
  if (samples_ > 0 && !(t > time_)) {
    return VelocityFilterVerdict::kNotIncreasing;
  }
  const double dt = t - time_;
  if (samples_ == 0 || dt > options_.max_gap) {
    samples_ = 1;
    time_ = t;
    position_ = p;
    return VelocityFilterVerdict::kStarted;
  }
  if (samples_ == 1) {
    velocity_ = (p - position_) / dt;
    position_ = p;
    samples_ = 2;
  } else {
    const double theta = std::exp(-options_.bandwidth * dt);
    const Eigen::Vector3d predicted = position_ + velocity_ * dt;
    const Eigen::Vector3d residual = p - predicted;
    position_ = predicted + (1.0 - theta * theta) * residual;
    velocity_ += (1.0 - theta) * (1.0 - theta) / dt * residual;
  }
  time_ = t;
  if (!velocity_.allFinite()) {  // an overflow: start again rather than carry it on
    samples_ = 0;
    return VelocityFilterVerdict::kRefused;
  }
  state->resize(2 * k);
  state->head(k) = p.head(k);
  state->tail(k) = velocity_.head(k);
  return VelocityFilterVerdict::kEstimated;
}

}  // namespace projection_collision_avoidance
