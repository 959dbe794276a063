#pragma once

/// @file
/// The Gamma-weighted projection operator of the CF estimator, in the form of doc/math.md
/// (which corrects eqs. (7), (12) and (15) of the paper).

#include <Eigen/Core>

#include "projection_collision_avoidance/core/BallConstraint.hpp"

namespace projection_collision_avoidance {

/// Projected estimator drift (replaces (12)/(15)):
///   xi_hat' = h - f Gamma^-1 grad_f (grad_f^T h) / (grad_f^T Gamma^-1 grad_f)
///             if f(xi_hat) > 0 and grad_f^T h > 0,   and xi_hat' = h otherwise.
/// On the boundary f = 1 this gives grad_f^T xi_hat' = 0 (Omega_1 is invariant), and the term
/// removed is Gamma^-1 grad_f times a non-negative scalar, which Theorem 3.1 needs.
/// Because grad_f is a positive multiple of xi_hat, xi_hat stands in for it (the factor cancels).
/// @param constraint the ball constraint f
/// @param estimate xi_hat (m)
/// @param drift h (m/s)
/// @param gamma_inverse Gamma^-1, symmetric positive definite
/// @param active set to true when the projection changes the drift, left unchanged otherwise
/// @return xi_hat' (m/s)
template <typename Vector, typename Matrix>
Vector projectDrift(const BallConstraint& constraint, const Vector& estimate, const Vector& drift,
                    const Matrix& gamma_inverse, bool* active) {
  const double f = constraint.value(estimate);
  const double outward = estimate.dot(drift);  // sign of grad_f^T h
  if (f > 0.0 && outward > 0.0) {
    const Vector weighted = gamma_inverse * estimate;  // direction of Gamma^-1 grad_f
    const double metric = estimate.dot(weighted);      // grad_f^T Gamma^-1 grad_f, > 0
    if (active != nullptr) {
      *active = true;
    }
    return drift - (f * outward / metric) * weighted;
  }
  return drift;
}

}  // namespace projection_collision_avoidance
