#pragma once

#include <cmath>

#include <Eigen/Core>

namespace projection_collision_avoidance {

/// The convex constraint (13) of the CF estimator:
/// f(x) = ((1 + eps) ||x||^2 - xi_max^2) / (eps xi_max^2),
/// whose sub-level sets are the soft ball Omega_0 = {f <= 0} of radius xi_max / sqrt(1 + eps)
/// (14a) and the hard ball Omega_1 = {f <= 1} of radius xi_max (14b).
class BallConstraint {
 public:
  /// @param xi_max hard radius (1 - alpha) ||d|| (m), > 0
  /// @param epsilon soft-boundary width, > 0
  BallConstraint(double xi_max, double epsilon)
      : xi_max_(xi_max),
        epsilon_(epsilon),
        scale_(1.0 / (epsilon * xi_max * xi_max)),
        gradient_scale_(2.0 * (1.0 + epsilon) / (epsilon * xi_max * xi_max)) {}

  /// f(x) (13), dimensionless.
  template <typename Derived>
  double value(const Eigen::MatrixBase<Derived>& x) const {
    return ((1.0 + epsilon_) * x.squaredNorm() - xi_max_ * xi_max_) * scale_;
  }

  /// grad f(x) = 2 (1 + eps) x / (eps xi_max^2) (1/m).
  template <typename Derived>
  auto gradient(const Eigen::MatrixBase<Derived>& x) const {
    return (gradient_scale_ * x).eval();
  }

  /// Radius of Omega_1 (m).
  double hardRadius() const { return xi_max_; }
  /// Radius of Omega_0 (m).
  double softRadius() const { return xi_max_ / std::sqrt(1.0 + epsilon_); }
  double epsilon() const { return epsilon_; }

 private:
  double xi_max_;
  double epsilon_;
  double scale_;
  double gradient_scale_;
};

}  // namespace projection_collision_avoidance
