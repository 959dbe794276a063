#pragma once

#include <limits>
#include <optional>
#include <string>

#include <Eigen/Core>

#include "projection_collision_avoidance/core/AgentModel.hpp"
#include "projection_collision_avoidance/core/SafetyFilter.hpp"

namespace projection_collision_avoidance {

/// How the CF estimate is initialised at the first control step.
enum class InitialEstimate {
  kMeasurement,  ///< xi_hat(0) = pinv(C) y_0, projected into Omega_1
  kZero,         ///< xi_hat(0) = 0
};

/// Everything the follower's controller needs, as read from configuration. Validate and derive
/// with ControllerDesign::create(); nothing here is trusted before that.
struct ControllerParameters {
  AgentModel model;                 ///< the agents' (A, B, C)
  double control_rate = 0.0;        ///< Hz
  Eigen::VectorXd separation;       ///< d in ker(A), n (m, and zero velocity)
  double alpha = 0.0;               ///< perimeter fraction, [0, 1)
  double epsilon = 0.0;             ///< soft-boundary width of the projection, > 0
  Eigen::MatrixXd baseline_gain;    ///< G, m x p (2)
  Eigen::MatrixXd estimator_gain;   ///< L, n x p (11)
  Eigen::MatrixXd lyapunov_weight;  ///< Q, n x n, symmetric positive definite
  int estimator_substeps = 1;       ///< RK4 steps of the estimator per control period
  InitialEstimate initial_estimate = InitialEstimate::kMeasurement;
  bool tracker_enabled = true;             ///< CF tracker (19) on or off
  Eigen::MatrixXd tracker_gain;            ///< G_e, m x p (19)
  Eigen::MatrixXd reference_gain;          ///< S_21, m x p (19)
  bool leader_input_in_command = false;    ///< add the leader's input u_1 to the command
  bool leader_input_in_estimator = false;  ///< model B (u_1 - u_ff) in the estimator drift
  /// The leader acceleration shared into the command and the estimator includes the acceleration
  /// part of the leader's disturbance, pinv(B) u_d, when the leader knows u_d: a_1 = u_1 +
  /// pinv(B) u_d. The rest of u_d, (I - B pinv(B)) u_d (the position-rate part of a double
  /// integrator's), is outside the range of B: no input can cancel it.
  bool leader_disturbance_shared = false;
  /// kappa of the shaped feed-forward (S2), in [0, 1]: u_ff scales the shared acceleration.
  double feedforward_gain = 1.0;
  /// tau (s) of the shaped feed-forward's first-order low-pass (S2); 0: none.
  double feedforward_time_constant = 0.0;
  /// h (s) of the constant time-headway spacing policy (S1): the slot moves back by h v_2, the
  /// follower's velocity; 0: the paper's constant d. Double integrators only.
  double time_headway = 0.0;
  /// Bound on the command's norm ||u_2|| (m/s^2 for double integrators); a larger command is
  /// scaled onto it. Infinity: no bound.
  double acceleration_limit = std::numeric_limits<double>::infinity();
  /// Bound on the command's rate of change (m/s^3 for double integrators): after saturation,
  /// ||u_2(k) - u_2(k-1)|| <= jerk_limit T, in tracking and fallback steps alike, with u_2 = 0
  /// before the first step. Infinity: no bound.
  double jerk_limit = std::numeric_limits<double>::infinity();
  /// Gain K_f (m x n) of the fallback that runs while no measurement arrives:
  /// u_2 = sat(u_ff + K_f xi_hat), xi_hat predicted without correction. Empty: the default,
  /// [0, I / s] for double integrators (brake the relative velocity with a 1 s time constant),
  /// zero otherwise.
  Eigen::MatrixXd fallback_gain;
  /// controller.safety_filter: when given, the follower runs the control barrier function filter
  /// (doc/math.md (B1)-(B3)) in place of the CF tracker: the baseline law's command (tracker
  /// disabled) filtered by the barrier (B2) on the distance to its target, perimeter alpha ||d||,
  /// within acceleration_limit. The CF estimator still runs and is reported; it does not act.
  std::optional<SafetyFilterParameters> safety_filter;
};

/// The default fallback gain of a k-axis double integrator: [0, k_v I], so that the fallback
/// command u_2 = u_ff + k_v v_hat brakes the relative velocity v_1 - v_2 at the rate k_v (1/s).
Eigen::MatrixXd doubleIntegratorFallbackGain(int axes, double velocity_gain);

/// Gain matrix of a k-axis double integrator with C = I from per-axis natural frequency
/// omega_n (rad/s) and damping zeta: row i is omega_i^2 on p_i and 2 zeta_i omega_i on v_i, so
/// that u = G xi places the poles of p_i'' = -u_i at s^2 + 2 zeta_i omega_i s + omega_i^2.
/// Throws ParameterError(key) if the sizes differ from k or a value is not positive and finite.
Eigen::MatrixXd doubleIntegratorGain(const Eigen::VectorXd& natural_frequency,
                                     const Eigen::VectorXd& damping, const std::string& key);

}  // namespace projection_collision_avoidance
