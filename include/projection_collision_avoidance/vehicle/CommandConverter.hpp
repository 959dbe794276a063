#pragma once

/// @file
/// The follower's acceleration command a (world frame, m/s²) turned into what a vehicle stack
/// takes: the acceleration itself (MAVROS setpoint_accel), a velocity (Twist) in the world or the
/// base frame, or a unicycle's (v, ω); and each kind's stop (doc/vehicles.md).

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "projection_collision_avoidance/vehicle/RelativeStateFromOdometry.hpp"
#include "projection_collision_avoidance/vehicle/UnicycleLookAhead.hpp"
#include "projection_collision_avoidance/vehicle/VelocityCommandIntegrator.hpp"

namespace projection_collision_avoidance {

/// Options of CommandConverter.
struct CommandConverterOptions {
  int axes = 2;                   ///< of the follower's model: 2 or 3
  double period = 0.01;           ///< T (s): the follower's control period, > 0
  double max_odometry_age = 0.1;  ///< s; an older own odometry is not used (heading, anchor)
  TwistFrame odometry_twist_frame = TwistFrame::kBody;  ///< of the own odometry (REP 105: body)
  VelocityIntegratorOptions velocity;   ///< axes set from `axes` (2 for the unicycle)
  bool velocity_in_base_frame = false;  ///< the velocity command in the base frame, not world
  bool unicycle = false;                ///< map the velocity through the look-ahead point
  double look_ahead = 0.2;              ///< l (m) of the unicycle's controlled point
  UnicycleLimits unicycle_limits;
  /// Deceleration (m/s², > 0) of the acceleration output's stop: a = −v/‖v‖ · min(this, ‖v‖/T)
  /// from the fresh measured velocity; zero without one.
  double stop_deceleration = 1.0;
};

/// One converted command: every kind, so that any set of outputs can be sent.
struct ConvertedCommand {
  Eigen::Vector3d acceleration = Eigen::Vector3d::Zero();  ///< world frame (m/s²)
  /// The velocity command (m/s): world frame, or the base frame with velocity_in_base_frame.
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();
  UnicycleCommand unicycle;  ///< (v, ω) with what the limits did (unicycle only)
  VelocityAnchor anchor = VelocityAnchor::kPreviousCommand;
  bool speed_limited = false;  ///< the velocity was scaled onto max_speed
  bool heading_known = true;   ///< false: no fresh own odometry for a base-frame or unicycle map
  bool stop = false;           ///< this is the stop of each kind
  /// The conversion gave a non-finite value (an overflow of huge finite inputs): this is the
  /// stop in its place.
  bool replaced_non_finite = false;
};

/// Whether every value a vehicle would be sent (acceleration, velocity, (v, ω)) is finite.
bool isFinite(const ConvertedCommand& command);

/// Converts the follower's commands, one per control period, with the vehicle's own odometry:
/// - acceleration: a as it is;
/// - velocity: v_cmd = clamp(anchor + a h) (VelocityCommandIntegrator, anchored on the fresh
///   measured velocity of the controlled point, else the previous command), rotated into the base
///   frame (R(q)ᵀ v_cmd) with velocity_in_base_frame;
/// - unicycle: the same on the look-ahead point p + l [cos θ, sin θ], then (v, ω) by the inverse
///   look-ahead map with the limits (UnicycleLookAhead::command()); the integrator is told what
///   was sent (s ṗ_l).
/// A base-frame velocity or a unicycle command needs the heading: without a fresh own odometry
/// the converter sends the stop and says heading_known = false. A conversion that is not finite
/// (huge finite inputs whose products overflow) gives the stop instead, with
/// replaced_non_finite = true: every command given is finite. Never throws on inputs;
/// allocates nothing.
class CommandConverter {
 public:
  /// @throws ParameterError (the vehicle layer's keys) for invalid options
  explicit CommandConverter(const CommandConverterOptions& options);

  /// Notes the vehicle's own odometry (any frame of origin: only its orientation and velocity are
  /// used). A sample equal in every value to the previous one is the same state published
  /// again: its state is dated by the first of them (stateChangedAt()).
  /// @return false (nothing noted) if not finite or its quaternion is not unit.
  bool observe(const OdometrySample& own);

  /// The conversion of the follower's acceleration @p acceleration (axes entries, m/s², world
  /// frame) at time @p now (s).
  const ConvertedCommand& convert(const Eigen::Ref<const Eigen::VectorXd>& acceleration,
                                  double now);

  /// Each kind's stop at @p now (s): zero velocity, zero (v, ω), and for the acceleration a
  /// braking one (zero if that is not finite); the integrator starts again from rest.
  const ConvertedCommand& stop(double now);

  const CommandConverterOptions& options() const { return options_; }
  /// How the vehicle follows the velocity commands (VehicleResponseEstimator).
  const VehicleResponse& response() const { return integrator_.response(); }
  /// The response delay D (s) the velocity commands are built with.
  double delay() const { return integrator_.delay(); }
  /// When the own odometry's state last changed (s): earlier than its stamp for a vehicle whose
  /// state changes less often than its odometry is published.
  double stateChangedAt() const { return own_changed_at_; }

 private:
  /// Whether the own odometry is fresh at @p now.
  bool fresh(double now) const;
  /// World velocity (m/s) of the controlled point (origin, or look-ahead point) of the own sample.
  Eigen::Vector3d controlledPointVelocity() const;

  CommandConverterOptions options_;
  VelocityCommandIntegrator integrator_;
  UnicycleLookAhead look_ahead_;
  OdometrySample own_;
  double own_changed_at_ = 0.0;
  bool have_own_ = false;
  ConvertedCommand out_;
};

}  // namespace projection_collision_avoidance
