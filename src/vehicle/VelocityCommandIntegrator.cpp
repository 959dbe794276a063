#include "projection_collision_avoidance/vehicle/VelocityCommandIntegrator.hpp"

#include <cmath>
#include <string>

#include "projection_collision_avoidance/core/BallConstraint.hpp"
#include "projection_collision_avoidance/core/ParameterError.hpp"

namespace projection_collision_avoidance {

double velocityLead(double period, double velocity_lag) {
  if (!(velocity_lag > 0.0)) {
    return period;
  }
  // 1 − e^(−x) by expm1 keeps its digits when T ≪ τ.
  return period / -std::expm1(-period / velocity_lag);
}

VelocityCommandIntegrator::VelocityCommandIntegrator(const VelocityIntegratorOptions& options)
    : options_(options) {
  if (options.axes < 1 || options.axes > 3) {
    throw ParameterError("vehicle.velocity.axes",
                         "must be 1, 2 or 3, got " + std::to_string(options.axes));
  }
  if (!(options.max_speed > 0.0)) {
    throw ParameterError("vehicle.velocity.max_speed", "must be > 0 m/s (or infinity: none), got " +
                                                           std::to_string(options.max_speed));
  }
  if (!(options.max_measurement_age >= 0.0) || !std::isfinite(options.max_measurement_age)) {
    throw ParameterError(
        "vehicle.velocity.max_measurement_age",
        "must be finite and >= 0 s, got " + std::to_string(options.max_measurement_age));
  }
  if (!(options.velocity_lag >= 0.0) || !std::isfinite(options.velocity_lag)) {
    throw ParameterError("vehicle.velocity.velocity_lag",
                         "must be finite and >= 0 s, got " + std::to_string(options.velocity_lag));
  }
  measured_ = AxisVector::Zero(options.axes);
  command_.velocity = AxisVector::Zero(options.axes);
}

bool VelocityCommandIntegrator::measure(const AxisVector& velocity, double stamp) {
  if (velocity.size() != options_.axes || !velocity.allFinite() || !std::isfinite(stamp)) {
    return false;
  }
  measured_ = velocity;
  measured_stamp_ = stamp;
  have_measurement_ = true;
  return true;
}

const VelocityCommand& VelocityCommandIntegrator::step(const AxisVector& acceleration,
                                                       double period, double now) {
  // Written so that a NaN now makes the measurement stale.
  const bool fresh =
      have_measurement_ && std::abs(now - measured_stamp_) <= options_.max_measurement_age;
  AxisVector anchor = fresh ? measured_ : command_.velocity;
  command_.anchor = fresh ? VelocityAnchor::kMeasured : VelocityAnchor::kPreviousCommand;
  command_.limited = false;
  command_.refused = acceleration.size() != options_.axes || !acceleration.allFinite() ||
                     !(period > 0.0) || !std::isfinite(period);
  if (!command_.refused) {
    const double lead = fresh ? velocityLead(period, options_.velocity_lag) : period;
    const AxisVector next = anchor + acceleration * lead;
    if (next.allFinite()) {
      anchor = next;
    } else {  // finite inputs whose sum overflows
      command_.refused = true;
    }
  }
  command_.limited = clampNorm(anchor, options_.max_speed) > 0.0;
  command_.velocity = anchor;
  return command_;
}

void VelocityCommandIntegrator::setSent(const AxisVector& velocity) {
  if (velocity.size() == options_.axes && velocity.allFinite()) {
    command_.velocity = velocity;
  }
}

void VelocityCommandIntegrator::reset() {
  measured_.setZero();
  have_measurement_ = false;
  command_ = VelocityCommand();
  command_.velocity = AxisVector::Zero(options_.axes);
}

}  // namespace projection_collision_avoidance
