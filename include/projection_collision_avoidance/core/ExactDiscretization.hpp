#pragma once

#include <Eigen/Core>

namespace projection_collision_avoidance {

/// Exact zero-order-hold discretisation of x' = A x + v with v constant over a step of length
/// dt: x(t + dt) = Phi x(t) + Psi v, Phi = e^{A dt}, Psi = int_0^dt e^{A s} ds, both read off
/// the exponential of the augmented matrix [[A, I], [0, 0]] dt.
struct ExactDiscretization {
  Eigen::MatrixXd transition;  ///< Phi
  Eigen::MatrixXd integral;    ///< Psi (s)

  /// @param A n x n state matrix
  /// @param dt step length (s), >= 0
  static ExactDiscretization compute(const Eigen::MatrixXd& A, double dt);
};

}  // namespace projection_collision_avoidance
