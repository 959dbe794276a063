#pragma once

/// @file
/// The follower's acceleration command a (m/s²) turned into a velocity command (m/s) for
/// velocity-controlled vehicles (Twist, TwistStamped, MAVROS velocity setpoints), without
/// integrator wind-up (doc/vehicles.md).

#include <limits>

#include <Eigen/Core>

#include "projection_collision_avoidance/core/TypeDefs.hpp"
#include "projection_collision_avoidance/vehicle/AxisVector.hpp"
#include "projection_collision_avoidance/vehicle/CommandHistory.hpp"
#include "projection_collision_avoidance/vehicle/VehicleResponseEstimator.hpp"

namespace projection_collision_avoidance {

/// What the velocity command was built on.
enum class VelocityAnchor {
  kMeasured,         ///< the vehicle's fresh measured velocity
  kPreviousCommand,  ///< the previous command (no fresh measurement)
};

/// Options of VelocityCommandIntegrator.
struct VelocityIntegratorOptions {
  int axes = 2;  ///< 1, 2 or 3
  /// ‖v_cmd‖ ≤ max_speed (m/s), > 0; infinity: none
  double max_speed = std::numeric_limits<double>::infinity();
  /// A measured velocity is fresh while |now − its stamp| ≤ max_measurement_age (s), ≥ 0
  double max_measurement_age = 0.1;
  /// τ (s), ≥ 0: the time constant of the vehicle's velocity loop, v̇ = (v_cmd − v) / τ; 0 for
  /// a vehicle that reaches its command within a period
  double velocity_lag = 0.0;
  /// T (s), > 0: the control period, the spacing of the candidate delays
  double period = 0.01;
  /// D (s): the measured velocity is the command in force D before it was taken; < 0: estimated
  /// (VehicleResponseEstimator), ≤ max_delay. Not used with a velocity_lag (> 0).
  double delay = -1.0;
  /// s, ≥ 0, ≤ 255 T: the longest delay estimated; commands are predicted over at most
  /// 2 max_delay past a measurement
  double max_delay = 0.3;
  /// s, > 0: the memory of the response estimates
  double averaging_time = 1.0;
};

/// One velocity command and how it was made.
struct VelocityCommand {
  AxisVector velocity;  ///< v_cmd (m/s), in the frame of the acceleration (the world frame)
  VelocityAnchor anchor = VelocityAnchor::kPreviousCommand;
  bool limited = false;  ///< ‖anchor + a h‖ exceeded max_speed: scaled onto it (same direction)
  /// a or T not finite, T ≤ 0, a of the wrong size, or anchor + a h overflowing:
  /// v_cmd = clamp(anchor)
  bool refused = false;
};

/// The lead h (s) by which the command leads the measured velocity, so that a vehicle with a
/// first-order velocity lag τ sampled every T gains a T per period: h = T / (1 − e^(−T/τ)),
/// h = T for τ = 0 (h ≥ T; h ≈ τ + T/2 for τ ≫ T).
double velocityLead(double period, double velocity_lag);

/// v_cmd(k+1) = clamp(v_anchor + a h, max_speed):
/// - anchor = the measured velocity v_m when fresh, brought up to date with the commands it does
///   not show yet: v_anchor = v_m + Σ Δc_j over the commands sent at or after t_m − D (t_m: when
///   the measured state changed last, D: the response delay; Δc_j = a_j T, what command j asks
///   of the vehicle over a period, less when a limit acted), h = velocityLead(T, τ). The command is
///   a fixed lead ahead of what the vehicle will do, so when the vehicle's own controller
///   saturates (it cannot follow) the command stays within the increments of the last
///   2 max_delay of v_measured instead of growing: no wind-up beyond that bound.
/// - anchor = the previous command when the measurement is not fresh, h = T: a plain integrator,
///   whose state is the limited command itself (clamping anti-windup at max_speed).
/// clamp() scales a vector longer than max_speed onto it, keeping its direction (clampNorm()).
/// Before the first command the previous one is zero (a vehicle at rest). Never throws on inputs
/// and allocates nothing.
class VelocityCommandIntegrator {
 public:
  /// @throws ParameterError naming vehicle.velocity.axes, .max_speed, .max_measurement_age or
  ///         .velocity_lag
  explicit VelocityCommandIntegrator(const VelocityIntegratorOptions& options);

  /// Notes the vehicle's measured velocity (m/s, the command's frame) at @p stamp (s), a state
  /// that changed last at @p changed_at (s, ≤ stamp: a vehicle whose state changes less often
  /// than it is published); a new changed_at is a change of state for the response estimate.
  /// @return false (and nothing noted) if not finite or not of the options' axes
  bool measure(const AxisVector& velocity, double stamp, double changed_at);
  /// measure() of a state taken at @p stamp.
  bool measure(const AxisVector& velocity, double stamp) { return measure(velocity, stamp, stamp); }

  /// The command for the follower's acceleration @p acceleration (m/s²) over the period
  /// @p period (s) at time @p now (s); it becomes the previous command.
  const VelocityCommand& step(const AxisVector& acceleration, double period, double now);

  /// Replaces the previous command by what was actually sent after limits further down (the
  /// unicycle's: s ṗ_l), so that an integration without measurements starts from it. Ignored if
  /// not finite or of the wrong size.
  void setSent(const AxisVector& velocity);

  /// Back to rest: previous command zero, no measurement, no history (the response estimate
  /// is kept: it describes the vehicle).
  void reset();

  const VelocityCommand& last() const { return command_; }
  const VelocityIntegratorOptions& options() const { return options_; }
  /// The vehicle's response as estimated so far.
  const VehicleResponse& response() const { return estimator_.response(); }
  /// The response delay D (s) the anchor uses.
  double delay() const;

 private:
  VelocityIntegratorOptions options_;
  CommandHistory history_;
  VehicleResponseEstimator estimator_;
  AxisVector measured_;
  double measured_stamp_ = 0.0;
  double measured_changed_at_ = 0.0;
  bool have_measurement_ = false;
  double increment_scale_ = 1.0;  ///< T / h of the last step
  VelocityCommand command_;
};

}  // namespace projection_collision_avoidance
