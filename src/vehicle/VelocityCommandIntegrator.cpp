#include "projection_collision_avoidance/vehicle/VelocityCommandIntegrator.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
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

namespace {

ResponseEstimatorOptions estimatorOptions(const VelocityIntegratorOptions& options) {
  ResponseEstimatorOptions estimator;
  estimator.period = options.period;
  estimator.max_delay = options.max_delay;
  estimator.averaging_time = options.averaging_time;
  return estimator;
}

/// Commands kept: a delay and a hold, each up to max_delay, and the estimator's segment
/// (validated by the estimator first).
std::size_t historyCapacity(const VelocityIntegratorOptions& options) {
  const VehicleResponseEstimator check(estimatorOptions(options));
  const double segment = check.options().segment / options.period;
  return 2 * static_cast<std::size_t>(check.candidates()) + 2 +
         static_cast<std::size_t>(std::ceil(std::min(segment, 1e4)));
}

int checkedAxes(int axes) {
  if (axes < 1 || axes > 3) {
    throw ParameterError("vehicle.velocity.axes", "must be 1, 2 or 3, got " + std::to_string(axes));
  }
  return axes;
}

}  // namespace

VelocityCommandIntegrator::VelocityCommandIntegrator(const VelocityIntegratorOptions& options)
    : options_(options),
      history_(historyCapacity(options), checkedAxes(options.axes)),
      estimator_(estimatorOptions(options)) {
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
  if (!(options.delay <= options.max_delay)) {
    throw ParameterError("vehicle.velocity.delay",
                         "must be <= max_delay (" + std::to_string(options.max_delay) +
                             " s), or < 0 to estimate it, got " + std::to_string(options.delay));
  }
  measured_ = AxisVector::Zero(options.axes);
  command_.velocity = AxisVector::Zero(options.axes);
}

bool VelocityCommandIntegrator::measure(const AxisVector& velocity, double stamp,
                                        double changed_at) {
  if (velocity.size() != options_.axes || !velocity.allFinite() || !std::isfinite(stamp) ||
      !std::isfinite(changed_at)) {
    return false;
  }
  changed_at = std::min(changed_at, stamp);
  if (!have_measurement_ || changed_at != measured_changed_at_) {
    estimator_.observe(velocity, changed_at, history_);
  }
  measured_ = velocity;
  measured_stamp_ = stamp;
  measured_changed_at_ = changed_at;
  have_measurement_ = true;
  return true;
}

double VelocityCommandIntegrator::delay() const {
  if (options_.velocity_lag > 0.0) {
    return 0.0;
  }
  return options_.delay >= 0.0 ? options_.delay : estimator_.response().delay;
}

const VelocityCommand& VelocityCommandIntegrator::step(const AxisVector& acceleration,
                                                       double period, double now) {
  // Written so that a NaN now makes the measurement stale.
  const bool fresh =
      have_measurement_ && std::abs(now - measured_stamp_) <= options_.max_measurement_age;
  if (history_.size() > 0 && !(now >= history_.fromNewest(0).time)) {
    history_.clear();  // time went back: the commands sent "later" are of another timeline
  }
  AxisVector anchor = command_.velocity;
  if (fresh) {  // the measurement and the commands sent since the state it shows
    // At most 2 max_delay + 2 T of commands: a vehicle that cannot follow winds up no further.
    const double from = std::max(measured_changed_at_ - delay(),
                                 now - 2.0 * (options_.max_delay + options_.period));
    anchor = measured_ + history_.incrementBetween(from, std::numeric_limits<double>::infinity());
  }
  if (!anchor.allFinite()) {  // increments that overflow: start from the measurement alone
    anchor = measured_;
  }
  const AxisVector base = anchor;
  command_.anchor = fresh ? VelocityAnchor::kMeasured : VelocityAnchor::kPreviousCommand;
  command_.limited = false;
  command_.refused = acceleration.size() != options_.axes || !acceleration.allFinite() ||
                     !(period > 0.0) || !std::isfinite(period);
  // The history keeps what each command asks of the vehicle over a period, a T: its increment
  // over the anchor, a h, times T / h (for a lagging vehicle h > T).
  increment_scale_ = 1.0;
  if (!command_.refused) {
    const double lead = fresh ? velocityLead(period, options_.velocity_lag) : period;
    increment_scale_ = period / lead;
    const AxisVector next = anchor + acceleration * lead;
    if (next.allFinite()) {
      anchor = next;
    } else {  // finite inputs whose sum overflows
      command_.refused = true;
    }
  }
  command_.limited = clampNorm(anchor, options_.max_speed) > 0.0;
  history_.push(now, anchor, (anchor - base) * increment_scale_);
  command_.velocity = anchor;
  return command_;
}

void VelocityCommandIntegrator::setSent(const AxisVector& velocity) {
  if (velocity.size() == options_.axes && velocity.allFinite()) {
    command_.velocity = velocity;
    history_.replaceNewest(velocity, increment_scale_);
  }
}

void VelocityCommandIntegrator::reset() {
  measured_.setZero();
  have_measurement_ = false;
  history_.clear();
  command_ = VelocityCommand();
  command_.velocity = AxisVector::Zero(options_.axes);
}

}  // namespace projection_collision_avoidance
