#pragma once

#include <Eigen/Core>

#include "projection_collision_avoidance/core/ControllerParameters.hpp"

namespace projection_collision_avoidance {

/// Validated controller parameters and the quantities derived from them once, at load time.
/// The only way to make one is create(), which refuses any parameter set the theory does not
/// cover, naming the offending key (there is no default constructor; copies are designs too).
/// Its fields are read, never written, outside create().
class ControllerDesign {
 public:
  ControllerParameters parameters;
  double period = 0.0;                   ///< control period T = 1 / control_rate (s)
  double xi_max = 0.0;                   ///< hard bound (1 - alpha) ||d|| (4) (m)
  double xi_soft = 0.0;                  ///< soft bound xi_max / sqrt(1 + epsilon) (14a) (m)
  double perimeter = 0.0;                ///< safety perimeter alpha ||d|| (m)
  Eigen::MatrixXd closed_loop;           ///< A_c = A - B G C (3)
  Eigen::MatrixXd estimator_matrix;      ///< A_c + L C (11)
  Eigen::MatrixXd tracking_matrix;       ///< A_c - B G_e C (26a)
  Eigen::MatrixXd gamma;                 ///< Gamma: Gamma (A_c + L C) + (A_c + L C)^T Gamma = -Q
  Eigen::MatrixXd gamma_inverse;         ///< Gamma^-1
  double lyapunov_residual = 0.0;        ///< ||Gamma F + F^T Gamma + Q||_F / ||Q||_F
  Eigen::MatrixXd output_pseudoinverse;  ///< pinv(C), n x p, for the initial estimate
  Eigen::MatrixXd input_pseudoinverse;   ///< pinv(B), m x n: the acceleration part of u_d
  Eigen::MatrixXd fallback_gain;         ///< K_f, m x n (parameters.fallback_gain or its default)
  Eigen::MatrixXd fallback_matrix;       ///< A - B K_f: the predicted xi' in the fallback
  Eigen::MatrixXd headway_gain;          ///< K_h = -G C M of the time headway (S1), m x n
  double feedforward_smoothing = 0.0;    ///< a = exp(-T / tau) of the shaped feed-forward (S2)
  /// Decay rate mu = lambda_min(Q) / (2 lambda_max(Gamma)) of Theorem 3.1: ||e(t)|| <=
  /// K_0 e^{-mu t / 2} ||e(0)|| with K_0 = sqrt(lambda_max(Gamma) / lambda_min(Gamma)).
  double estimator_decay_rate = 0.0;
  double estimator_overshoot = 0.0;  ///< K_0 of Theorem 3.1

  /// Validates @p parameters and derives the design. Throws ParameterError with the key of the
  /// first failing check: sizes and finiteness of every matrix, alpha in [0, 1), epsilon > 0,
  /// acceleration_limit and jerk_limit > 0 (or infinite), d != 0 and A d = 0, control_rate > 0,
  /// substeps in [1, 1000], Q = Q^T > 0, and A_c, A_c + L C, A_c - B G_e C Hurwitz (the message
  /// lists the eigenvalues), K_f of size m x n, finite, with no eigenvalue of A - B K_f in the open
  /// right half-plane, and the string-stability options (validatePlatoonParameters()).
  static ControllerDesign create(const ControllerParameters& parameters);

  /// The leader's acceleration as shared with the follower: a_1 = u_1 + pinv(B) u_d when
  /// parameters.leader_disturbance_shared and u_d is known (@p disturbance non-empty), else u_1.
  /// For a double integrator pinv(B) u_d is the velocity-rate part of u_d (m/s^2).
  /// @param leader_input u_1 (m entries, m/s^2)
  /// @param disturbance u_d (n entries: m/s, then m/s^2), or empty when unknown
  Eigen::VectorXd leaderAcceleration(const Eigen::VectorXd& leader_input,
                                     const Eigen::VectorXd& disturbance) const;

 private:
  ControllerDesign() = default;
};

}  // namespace projection_collision_avoidance
