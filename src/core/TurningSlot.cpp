#include "projection_collision_avoidance/core/TurningSlot.hpp"

#include <algorithm>
#include <cmath>

#include "projection_collision_avoidance/core/ParameterError.hpp"

namespace projection_collision_avoidance {
namespace {

constexpr double kPi = 3.14159265358979323846;

void requirePositive(double value, const std::string& key) {
  if (!std::isfinite(value) || value <= 0.0) {
    throw ParameterError(key, "must be finite and > 0, got " + std::to_string(value));
  }
}

}  // namespace

void SlotHeadingParameters::validate(const std::string& prefix) const {
  requirePositive(natural_frequency, prefix + ".natural_frequency");
  requirePositive(damping, prefix + ".damping");
  requirePositive(max_yaw_rate, prefix + ".max_yaw_rate");
  requirePositive(max_yaw_acceleration, prefix + ".max_yaw_acceleration");
  if (!std::isfinite(min_speed) || min_speed < 0.0) {
    throw ParameterError(prefix + ".min_speed",
                         "must be finite and >= 0, got " + std::to_string(min_speed));
  }
}

std::optional<double> velocityHeading(double velocity_x, double velocity_y, double min_speed) {
  const double speed = std::hypot(velocity_x, velocity_y);
  if (!std::isfinite(speed) || speed < min_speed || speed == 0.0) {
    return std::nullopt;
  }
  return std::atan2(velocity_y, velocity_x);
}

double wrapAngle(double angle) {
  if (!std::isfinite(angle)) {
    return std::nan("");
  }
  double wrapped = std::remainder(angle, 2.0 * kPi);  // in [-pi, pi]
  if (wrapped <= -kPi) {
    wrapped += 2.0 * kPi;
  }
  return wrapped;
}

SlotHeading::SlotHeading(const SlotHeadingParameters& parameters, double period)
    : parameters_(parameters), period_(period) {}

void SlotHeading::reset(double angle) {
  angle_ = std::isfinite(angle) ? angle : 0.0;
  rate_ = 0.0;
  previous_heading_.reset();
}

SlotHeadingSample SlotHeading::tick(std::optional<double> heading) {
  if (heading && !std::isfinite(*heading)) {
    heading.reset();
  }
  double heading_error = 0.0;  // wrap(psi - theta)
  double heading_rate = 0.0;   // psi', from the two latest headings
  if (heading && parameters_.reversing && std::abs(wrapAngle(*heading - angle_)) > 0.5 * kPi) {
    heading = wrapAngle(*heading + kPi);  // driving backward: its body points the other way
  }
  if (heading) {
    heading_error = wrapAngle(*heading - angle_);
    if (previous_heading_) {
      heading_rate = wrapAngle(*heading - *previous_heading_) / period_;
    }
  }
  previous_heading_ = heading;
  const double omega = parameters_.natural_frequency;
  double acceleration = omega * omega * heading_error +
                        2.0 * parameters_.damping * omega * (heading_rate - rate_);  // (T1)
  const double beta = parameters_.max_yaw_acceleration;
  acceleration = std::clamp(acceleration, -beta, beta);
  // |theta'| <= max_yaw_rate at the end of the period (a rate already beyond it is brought back).
  const double max_rate = parameters_.max_yaw_rate;
  const double lowest = std::max(-beta, (-max_rate - rate_) / period_);
  const double highest = std::min(beta, (max_rate - rate_) / period_);
  if (lowest <= highest) {
    acceleration = std::clamp(acceleration, lowest, highest);
  } else {  // more than beta T beyond the bound: back toward it at beta
    acceleration = rate_ > 0.0 ? -beta : beta;
  }
  const SlotHeadingSample sample{angle_, rate_, acceleration};
  angle_ += rate_ * period_ + 0.5 * acceleration * period_ * period_;
  rate_ += acceleration * period_;
  return sample;
}

}  // namespace projection_collision_avoidance
