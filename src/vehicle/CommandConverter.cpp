#include "projection_collision_avoidance/vehicle/CommandConverter.hpp"

#include <algorithm>
#include <cmath>

#include "projection_collision_avoidance/core/ParameterError.hpp"
#include "projection_collision_avoidance/vehicle/Rotation.hpp"

namespace projection_collision_avoidance {
namespace {

/// The integrator's options (the period checked first: the integrator is built before the body).
VelocityIntegratorOptions integratorOptions(const CommandConverterOptions& options) {
  if (!(options.period > 0.0) || !std::isfinite(options.period)) {
    throw ParameterError("vehicle.command.period", "must be finite and > 0");
  }
  VelocityIntegratorOptions velocity = options.velocity;
  velocity.axes = options.unicycle ? 2 : options.axes;
  velocity.period = options.period;
  return velocity;
}

/// The first entries of @p v (up to 3) on x, y, z; the rest zero.
Eigen::Vector3d padded(const Eigen::Ref<const Eigen::VectorXd>& v) {
  Eigen::Vector3d out = Eigen::Vector3d::Zero();
  const Eigen::Index n = std::min<Eigen::Index>(v.size(), 3);
  out.head(n) = v.head(n);
  return out;
}

}  // namespace

bool isFinite(const ConvertedCommand& command) {
  return command.acceleration.allFinite() && command.velocity.allFinite() &&
         std::isfinite(command.unicycle.velocity.v) &&
         std::isfinite(command.unicycle.velocity.omega);
}

CommandConverter::CommandConverter(const CommandConverterOptions& options)
    : options_(options),
      integrator_(integratorOptions(options)),
      look_ahead_(options.look_ahead, options.unicycle_limits) {
  if (options.axes < 1 || options.axes > 3) {
    throw ParameterError("vehicle.command.axes", "must be 1, 2 or 3");
  }
  if (options.unicycle && options.axes != 2) {
    throw ParameterError("vehicle.command.unicycle", "needs a planar (2-axis) model");
  }
  if (!(options.max_odometry_age >= 0.0) || !std::isfinite(options.max_odometry_age)) {
    throw ParameterError("vehicle.command.max_odometry_age", "must be finite and >= 0");
  }
  if (!(options.stop_deceleration > 0.0) || !std::isfinite(options.stop_deceleration)) {
    throw ParameterError("vehicle.command.stop_deceleration", "must be finite and > 0");
  }
}

bool CommandConverter::observe(const OdometrySample& own) {
  OdometrySample sample = own;
  if (!std::isfinite(sample.stamp) || !sample.position.allFinite() ||
      !sample.linear_velocity.allFinite() || !sample.angular_velocity.allFinite() ||
      normaliseQuaternion(sample.orientation, 1e-2) != QuaternionStatus::kUnit) {
    return false;
  }
  // A vehicle whose state changes less often than it is published repeats the same state
  // with a new stamp: its state was taken when it first appeared.
  const bool same_state = have_own_ && sample.position == own_.position &&
                          sample.orientation.coeffs() == own_.orientation.coeffs() &&
                          sample.linear_velocity == own_.linear_velocity &&
                          sample.angular_velocity == own_.angular_velocity &&
                          sample.stamp >= own_changed_at_;
  if (!same_state) {
    own_changed_at_ = sample.stamp;
  }
  own_ = sample;
  have_own_ = true;
  return true;
}

bool CommandConverter::fresh(double now) const {
  const double age = now - own_.stamp;
  return have_own_ && std::abs(age) <= options_.max_odometry_age;
}

Eigen::Vector3d CommandConverter::controlledPointVelocity() const {
  const Eigen::Vector3d r(options_.unicycle ? options_.look_ahead : 0.0, 0.0, 0.0);
  return bodyPointState(own_, r, options_.odometry_twist_frame).tail<3>();
}

const ConvertedCommand& CommandConverter::convert(
    const Eigen::Ref<const Eigen::VectorXd>& acceleration, double now) {
  out_ = ConvertedCommand();
  out_.acceleration = padded(acceleration);
  const bool have_heading = fresh(now);
  const int axes = integrator_.options().axes;
  if (have_heading) {
    integrator_.measure(controlledPointVelocity().head(axes), own_.stamp, own_changed_at_);
  }
  const VelocityCommand& command =
      integrator_.step(out_.acceleration.head(axes), options_.period, now);
  out_.anchor = command.anchor;
  out_.speed_limited = command.limited;
  out_.velocity = padded(command.velocity);
  const bool needs_heading = options_.unicycle || options_.velocity_in_base_frame;
  if (needs_heading && !have_heading) {  // no map into the base frame: each kind's stop
    out_.heading_known = false;
    out_.velocity.setZero();
    out_.unicycle = UnicycleCommand();
    integrator_.reset();
    return out_;
  }
  if (options_.unicycle) {
    const Eigen::Vector2d wanted = out_.velocity.head<2>();
    out_.unicycle = look_ahead_.command(yawOf(own_.orientation), wanted);
    integrator_.setSent(out_.unicycle.scale * wanted);
  }
  if (options_.velocity_in_base_frame) {
    out_.velocity = worldToBody(own_.orientation, out_.velocity);
  }
  if (!isFinite(out_)) {  // an overflow (R(q)ᵀ v of a huge v, a huge acceleration turned)
    stop(now);
    out_.replaced_non_finite = true;
  }
  return out_;
}

const ConvertedCommand& CommandConverter::stop(double now) {
  out_ = ConvertedCommand();
  out_.stop = true;
  integrator_.reset();
  if (fresh(now)) {
    const Eigen::Vector3d v =
        bodyPointState(own_, Eigen::Vector3d::Zero(), options_.odometry_twist_frame).tail<3>();
    Eigen::Vector3d planar = Eigen::Vector3d::Zero();
    planar.head(options_.axes) = v.head(options_.axes);
    const double speed = planar.norm();
    if (speed > 0.0) {
      out_.acceleration =
          -planar / speed * std::min(options_.stop_deceleration, speed / options_.period);
    }
  } else {
    out_.heading_known = !(options_.unicycle || options_.velocity_in_base_frame);
  }
  if (!out_.acceleration.allFinite()) {
    out_.acceleration.setZero();
  }
  return out_;
}

}  // namespace projection_collision_avoidance
