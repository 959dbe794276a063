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
    case VelocityFilterVerdict::kTooSoon:
      return "too soon";
    case VelocityFilterVerdict::kTooFast:
      return "too fast";
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
  if (!(options.min_interval > 0.0) || !(options.min_interval < options.max_gap)) {
    throw std::invalid_argument("min_interval must be > 0 s and < max_gap, got " +
                                std::to_string(options.min_interval));
  }
  if (!(options.max_speed > 0.0) || !std::isfinite(options.max_speed)) {
    throw std::invalid_argument("max_speed must be finite and > 0 m/s, got " +
                                std::to_string(options.max_speed));
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
  if (dt < options_.min_interval) {
    return VelocityFilterVerdict::kTooSoon;
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
  if (!(velocity_.head(k).norm() <= options_.max_speed)) {
    // No vehicle pair moves so fast: a glitch of one of the two positions. Clamping would hand
    // the controller a velocity as wrong in direction as in size; start again from this one
    // (a glitch in it is then refused at the next position, the measurement ages meanwhile).
    samples_ = 1;
    position_ = p;
    return VelocityFilterVerdict::kTooFast;
  }
  state->resize(2 * k);
  state->head(k) = p.head(k);
  state->tail(k) = velocity_.head(k);
  return VelocityFilterVerdict::kEstimated;
}

}  // namespace projection_collision_avoidance
