#include "projection_collision_avoidance/vehicle/UnicycleLookAhead.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "projection_collision_avoidance/core/ParameterError.hpp"

namespace projection_collision_avoidance {
namespace {

/// A limit is finite and > 0, or +infinity (none).
void requireLimit(double value, const std::string& key, const char* unit) {
  if (!(value > 0.0)) {  // also refuses NaN
    throw ParameterError(key, std::string("must be > 0 ") + unit + " (or infinity: none), got " +
                                  std::to_string(value));
  }
}

/// The factor that brings |value| within limit, 1 if it already is.
double limitScale(double value, double limit) {
  const double magnitude = std::abs(value);
  return magnitude > limit ? limit / magnitude : 1.0;
}

}  // namespace

UnicycleLookAhead::UnicycleLookAhead(double distance, const UnicycleLimits& limits)
    : distance_(distance), limits_(limits) {
  if (!(distance > 0.0) || !std::isfinite(distance)) {
    throw ParameterError("vehicle.unicycle.look_ahead_distance",
                         "must be finite and > 0 m, got " + std::to_string(distance));
  }
  requireLimit(limits.max_speed, "vehicle.unicycle.max_speed", "m/s");
  requireLimit(limits.max_yaw_rate, "vehicle.unicycle.max_yaw_rate", "rad/s");
}

Eigen::Vector2d UnicycleLookAhead::point(const UnicyclePose& pose) const {
  return Eigen::Vector2d(pose.x + distance_ * std::cos(pose.theta),
                         pose.y + distance_ * std::sin(pose.theta));
}

Eigen::Vector2d UnicycleLookAhead::velocity(double theta, const UnicycleVelocity& body) const {
  const double c = std::cos(theta);
  const double s = std::sin(theta);
  const double turn = distance_ * body.omega;
  return Eigen::Vector2d(body.v * c - turn * s, body.v * s + turn * c);
}

Eigen::Vector2d UnicycleLookAhead::velocityFromWorld(double theta,
                                                     const Eigen::Vector2d& axle_velocity,
                                                     double omega) const {
  const double turn = distance_ * omega;
  return axle_velocity + turn * Eigen::Vector2d(-std::sin(theta), std::cos(theta));
}

Eigen::Vector4d UnicycleLookAhead::state(const UnicyclePose& pose,
                                         const UnicycleVelocity& body) const {
  Eigen::Vector4d x;
  x << point(pose), velocity(pose.theta, body);
  return x;
}

UnicycleVelocity UnicycleLookAhead::inverse(double theta,
                                            const Eigen::Vector2d& look_ahead_velocity) const {
  const double c = std::cos(theta);
  const double s = std::sin(theta);
  const double x = look_ahead_velocity.x();
  const double y = look_ahead_velocity.y();
  UnicycleVelocity body;
  body.v = c * x + s * y;
  body.omega = (-s * x + c * y) / distance_;
  return body;
}

UnicycleCommand UnicycleLookAhead::command(double theta,
                                           const Eigen::Vector2d& look_ahead_velocity) const {
  UnicycleCommand command;
  if (!std::isfinite(theta) || !look_ahead_velocity.allFinite()) {
    command.refused = true;
    command.scale = 0.0;
    return command;
  }
  const UnicycleVelocity wanted = inverse(theta, look_ahead_velocity);
  if (!std::isfinite(wanted.v) || !std::isfinite(wanted.omega)) {  // overflow of ṗ_l / l
    command.refused = true;
    command.scale = 0.0;
    return command;
  }
  const double speed_scale = limitScale(wanted.v, limits_.max_speed);
  const double yaw_scale = limitScale(wanted.omega, limits_.max_yaw_rate);
  command.speed_limited = speed_scale < 1.0;
  command.yaw_rate_limited = yaw_scale < 1.0;
  command.scale = std::min(speed_scale, yaw_scale);
  command.velocity.v = command.scale * wanted.v;
  command.velocity.omega = command.scale * wanted.omega;
  // Rounding of the scaled product can exceed a limit by an ulp: clamp to it.
  command.velocity.v = std::clamp(command.velocity.v, -limits_.max_speed, limits_.max_speed);
  command.velocity.omega =
      std::clamp(command.velocity.omega, -limits_.max_yaw_rate, limits_.max_yaw_rate);
  return command;
}

double referenceDistanceLowerBound(double look_ahead_distance, double l_self, double l_target) {
  return std::max(0.0, look_ahead_distance - l_self - l_target);
}

double lookAheadPerimeter(double reference_perimeter, double l_self, double l_target) {
  return reference_perimeter + l_self + l_target;
}

}  // namespace projection_collision_avoidance
