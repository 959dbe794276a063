#pragma once

/// @file
/// Simulated vehicles that are not double integrators, as real robot bases behave: a holonomic
/// vehicle whose velocity follows a velocity command through a first-order lag (a multirotor in
/// velocity mode) and a differential-drive base (a unicycle) taking (v, ω). Both integrate
/// exactly over a step with the command held (the unicycle with a lag: to within the substeps
/// documented below). SI units; no allocation once constructed.

#include <limits>
#include <string>

#include <Eigen/Core>

namespace projection_collision_avoidance {

/// Parameters of a VelocityLagVehicle.
struct VelocityLagParameters {
  double velocity_lag = 0.0;  ///< τ (s), finite and ≥ 0; 0: the velocity takes the command at once
  double max_speed = std::numeric_limits<double>::infinity();  ///< m/s, > 0; +inf for none
  double heading = 0.0;  ///< ψ (rad), finite: the fixed yaw of the body frame in the world
};

/// A holonomic velocity-controlled vehicle in 1 to 3 world axes: v̇ = (v_cmd − v) / τ, ṗ = v.
/// Vectors are 3-vectors; the entries beyond the vehicle's axes stay 0. Its body frame is the
/// world frame turned by the fixed heading ψ about z.
class VelocityLagVehicle {
 public:
  /// @param axes k, 1 to 3
  /// @param position p(0) (m, world), entries beyond k ignored
  /// @param velocity v(0) (m/s, world), entries beyond k ignored
  /// @param key the parameters' name in errors: "<key>/velocity_lag" and so on
  /// @throws ParameterError naming <key>/velocity_lag, <key>/max_speed or <key>/heading
  /// @throws std::invalid_argument for axes outside [1, 3] or a non-finite initial state
  VelocityLagVehicle(int axes, const Eigen::Vector3d& position, const Eigen::Vector3d& velocity,
                     const VelocityLagParameters& parameters, const std::string& key = "vehicle");

  /// Holds the command v_cmd (m/s, world; entries beyond k ignored), scaled onto the speed limit
  /// when longer, keeping its direction: v_cmd ← v_cmd min(1, max_speed / ‖v_cmd‖).
  /// @return false, and the last valid command kept, for a non-finite entry
  bool setCommand(const Eigen::Vector3d& command);

  /// Integrates exactly over @p h (s, finite, ≥ 0) with the command held:
  /// v(h) = v_cmd + (v0 − v_cmd) e^(−h/τ), p(h) = p0 + v_cmd h + (v0 − v_cmd) τ (1 − e^(−h/τ));
  /// τ = 0: v(h) = v_cmd, p(h) = p0 + v_cmd h. @throws std::invalid_argument for another h
  void advance(double h);

  const Eigen::Vector3d& position() const { return position_; }  ///< p (m, world)
  const Eigen::Vector3d& velocity() const { return velocity_; }  ///< v (m/s, world)
  /// v in the body frame (m/s): v_body = R_z(ψ)ᵀ v.
  Eigen::Vector3d bodyVelocity() const;
  const Eigen::Vector3d& command() const { return command_; }  ///< v_cmd held (m/s, world)
  bool commandLimited() const { return limited_; }  ///< the speed limit scaled the held command
  double heading() const { return parameters_.heading; }  ///< ψ (rad)
  int axes() const { return axes_; }
  const VelocityLagParameters& parameters() const { return parameters_; }

 private:
  int axes_;
  VelocityLagParameters parameters_;
  Eigen::Vector3d position_;
  Eigen::Vector3d velocity_;
  Eigen::Vector3d command_ = Eigen::Vector3d::Zero();
  bool limited_ = false;
};

/// Parameters of a UnicycleVehicle.
struct UnicycleParameters {
  double velocity_lag = 0.0;  ///< τ (s) of v and ω, finite and ≥ 0; 0: no lag
  double max_speed = std::numeric_limits<double>::infinity();     ///< m/s, > 0; +inf for none
  double max_yaw_rate = std::numeric_limits<double>::infinity();  ///< rad/s, > 0; +inf for none
};

/// State of a unicycle: the axle's midpoint (x, y) (m), heading θ (rad, in [−π, π]), forward
/// speed v (m/s) and yaw rate ω (rad/s).
struct UnicycleState {
  double x = 0.0;
  double y = 0.0;
  double theta = 0.0;
  double v = 0.0;
  double omega = 0.0;
};

/// Moves (x, y, θ) along the arc of constant v (m/s) and ω (rad/s) for @p h (s), exactly:
/// θ1 = θ0 + ω h, x1 = x0 + v (sin θ1 − sin θ0) / ω, y1 = y0 − v (cos θ1 − cos θ0) / ω, evaluated
/// as x1 = x0 + v h cos(θ0 + ω h / 2) sinc(ω h / 2) (y likewise with sin), which is the straight
/// line x1 = x0 + v h cos θ0 at ω = 0 and loses no digits when |ω h| is tiny. θ is not wrapped.
void advanceArc(double v, double omega, double h, double* x, double* y, double* theta);

/// A differential-drive base: ẋ = v cos θ, ẏ = v sin θ, θ̇ = ω, and v̇ = (v_cmd − v) / τ,
/// ω̇ = (ω_cmd − ω) / τ (v = v_cmd, ω = ω_cmd at once for τ = 0).
///
/// A step of h with the command held: v and ω follow their exact lag solution; the step is cut
/// into n = substeps(h, τ) equal substeps h_s = h / n (1 for τ = 0, else
/// ceil(kSubstepsPerLag h / τ) within [kMinSubsteps, kMaxSubsteps]), and over each the pose
/// moves along the arc of v's and ω's exact means over that substep. So θ, v and ω are exact;
/// x and y are off by about h h_s² |v̇ ω − v ω̇| / 12 over the step (the arc's neglected
/// curvature of v e^(iθ)), and exact once v and ω are at their commands.
class UnicycleVehicle {
 public:
  static constexpr int kSubstepsPerLag = 16;  ///< substeps per τ of step
  static constexpr int kMinSubsteps = 8;      ///< with a lag
  static constexpr int kMaxSubsteps = 1024;   ///< with a lag

  /// @param initial the state at t = 0 (every entry finite)
  /// @param key the parameters' name in errors: "<key>/velocity_lag" and so on
  /// @throws ParameterError naming <key>/velocity_lag, <key>/max_speed or <key>/max_yaw_rate
  /// @throws std::invalid_argument for a non-finite initial state
  UnicycleVehicle(const UnicycleState& initial, const UnicycleParameters& parameters,
                  const std::string& key = "vehicle");

  /// Holds the command, each part clamped to its limit on its own (as a base's speed limiter):
  /// v_cmd ← clamp(v, ±max_speed), ω_cmd ← clamp(ω, ±max_yaw_rate); (m/s, rad/s).
  /// @return false, and the last valid command kept, if either is not finite
  bool setCommand(double v, double omega);

  /// Integrates over @p h (s, finite, ≥ 0) with the command held (see the class).
  /// @throws std::invalid_argument for another h
  void advance(double h);

  /// Substeps of a step of @p h (s) under the lag @p tau (s).
  static int substeps(double h, double tau);

  const UnicycleState& state() const { return state_; }
  /// The world velocity of the axle's midpoint (m/s): v [cos θ, sin θ].
  Eigen::Vector2d worldVelocity() const;
  double commandSpeed() const { return command_v_; }         ///< v_cmd held (m/s)
  double commandYawRate() const { return command_omega_; }   ///< ω_cmd held (rad/s)
  bool speedLimited() const { return speed_limited_; }       ///< max_speed clamped v_cmd
  bool yawRateLimited() const { return yaw_rate_limited_; }  ///< max_yaw_rate clamped ω_cmd
  const UnicycleParameters& parameters() const { return parameters_; }

 private:
  UnicycleParameters parameters_;
  UnicycleState state_;
  double command_v_ = 0.0;
  double command_omega_ = 0.0;
  bool speed_limited_ = false;
  bool yaw_rate_limited_ = false;
};

}  // namespace projection_collision_avoidance
