#pragma once

#include <algorithm>
#include <cmath>
#include <limits>

#include <Eigen/Core>

namespace projection_collision_avoidance {

/// Euclidean norm of a finite vector without overflow or underflow: Eigen's norm(),
/// sqrt(squaredNorm()), bit for bit, whenever the squared norm is a finite normal number, and
/// otherwise max|x_i| ||x / max|x_i|||. It is infinite only if the norm exceeds DBL_MAX. The bounds
/// of the controller (||xi_hat|| <= xi_max, ||u_2|| <= acceleration_limit) hold in this norm.
template <typename Derived>
double euclideanNorm(const Eigen::MatrixBase<Derived>& x) {
  const double squared = x.squaredNorm();
  if (squared >= std::numeric_limits<double>::min() &&
      squared <= std::numeric_limits<double>::max()) {
    return std::sqrt(squared);
  }
  const double largest = x.cwiseAbs().maxCoeff();
  if (!(largest > 0.0) || !std::isfinite(largest)) {
    return largest;  // zero, infinity or NaN
  }
  return largest * (x / largest).norm();
}

/// Scales the finite vector @p x along itself so that euclideanNorm(x) <= radius, if it is longer.
/// Works for every finite x and radius >= 0, also when ||x|| overflows or radius is subnormal.
/// @return euclideanNorm(x) before, if larger than radius (possibly infinite), else 0
template <typename Derived>
double clampNorm(Eigen::MatrixBase<Derived>& x, double radius) {
  const double norm = euclideanNorm(x);
  if (!(norm > radius)) {
    return 0.0;
  }
  if (!std::isfinite(norm)) {  // only the direction is representable
    x /= x.cwiseAbs().maxCoeff();
    x /= euclideanNorm(x);
    x *= radius;
  } else if (radius / norm >= std::numeric_limits<double>::min()) {
    x *= radius / norm;
  } else {  // a subnormal factor would carry few significant bits: normalise first
    x /= norm;
    x *= radius;
  }
  // Rounding can leave the scaled vector an ulp or so outside: shrink it until it is not, by a
  // factor whose distance from 1 doubles each time (the first, 2 ulps, is what normally
  // suffices), so that this ends within a few steps also among subnormal numbers.
  double shrink = 2.0 * std::numeric_limits<double>::epsilon();
  while (euclideanNorm(x) > radius) {
    x *= 1.0 - shrink;
    shrink = std::min(2.0 * shrink, 0.5);
  }
  return norm;
}

/// Hard bound (4) of transient stability (Definition 1.1): xi_max = (1 - alpha) ||d|| (m), the
/// radius of Omega_1.
inline double hardBound(double alpha, double separation_norm) {
  return (1.0 - alpha) * separation_norm;
}

/// Soft bound (14a): xi_max / sqrt(1 + epsilon) (m), the radius of Omega_0 = {f <= 0}.
inline double softBound(double xi_max, double epsilon) { return xi_max / std::sqrt(1.0 + epsilon); }

/// Safety perimeter alpha ||d|| (m): the least separation of the positions while (4) holds.
inline double safetyPerimeter(double alpha, double separation_norm) {
  return alpha * separation_norm;
}

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
        gradient_scale_(2.0 * (1.0 + epsilon) / (epsilon * xi_max * xi_max)),
        plain_(xi_max * xi_max >= std::numeric_limits<double>::min() &&
               xi_max * xi_max <= std::numeric_limits<double>::max()) {}

  /// f(x) (13), dimensionless, for finite x: as written while ||x||^2 is finite and xi_max^2 a
  /// finite normal number, otherwise (or if that gives NaN) as
  /// ((1 + eps) (||x|| / xi_max)^2 - 1) / eps, so that it is never NaN (it can be infinite).
  template <typename Derived>
  double value(const Eigen::MatrixBase<Derived>& x) const {
    const double squared = x.squaredNorm();
    if (plain_ && squared <= std::numeric_limits<double>::max()) {
      const double f = ((1.0 + epsilon_) * squared - xi_max_ * xi_max_) * scale_;
      if (!std::isnan(f)) {
        return f;
      }
    }
    const double norm = euclideanNorm(x);
    if (norm == 0.0) {
      return -1.0 / epsilon_;
    }
    const double ratio = norm / xi_max_;
    if (!(ratio < std::numeric_limits<double>::infinity())) {
      return std::numeric_limits<double>::infinity();
    }
    return ((1.0 + epsilon_) * ratio * ratio - 1.0) / epsilon_;
  }

  /// grad f(x) = 2 (1 + eps) x / (eps xi_max^2) (1/m).
  template <typename Derived>
  auto gradient(const Eigen::MatrixBase<Derived>& x) const {
    return (gradient_scale_ * x).eval();
  }

  /// Radius of Omega_1 (m).
  double hardRadius() const { return xi_max_; }
  /// Radius of Omega_0 (m).
  double softRadius() const { return softBound(xi_max_, epsilon_); }
  double epsilon() const { return epsilon_; }

 private:
  double xi_max_;
  double epsilon_;
  double scale_;
  double gradient_scale_;
  bool plain_;  // xi_max^2 is a finite normal number: value() as written
};

}  // namespace projection_collision_avoidance
