#pragma once

/// @file
/// Helpers of the sim layer's vehicle gtests: RK4 references and the key of a refused parameter.

#include <cmath>
#include <functional>
#include <limits>
#include <string>

#include <Eigen/Core>

#include "projection_collision_avoidance/core/ParameterError.hpp"

namespace projection_collision_avoidance {
namespace testing {

constexpr double kPi = 3.14159265358979323846;
constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

using State5 = Eigen::Matrix<double, 5, 1>;  // x, y, θ, v, ω

/// x' = f(x) integrated by classic RK4 over @p h in @p steps steps.
template <typename Vector>
Vector rk4(const std::function<Vector(const Vector&)>& f, Vector x, double h, int steps) {
  const double dt = h / steps;
  for (int i = 0; i < steps; ++i) {
    const Vector k1 = f(x);
    const Vector k2 = f(x + 0.5 * dt * k1);
    const Vector k3 = f(x + 0.5 * dt * k2);
    const Vector k4 = f(x + dt * k3);
    x += dt / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
  }
  return x;
}

/// The unicycle with a lag, v and ω towards (vc, ωc) with time constant τ, by RK4 (20,000 steps).
inline State5 unicycleReference(const State5& x0, double vc, double omegac, double tau, double h) {
  const std::function<State5(const State5&)> f = [=](const State5& s) {
    State5 d;
    d << s(3) * std::cos(s(2)), s(3) * std::sin(s(2)), s(4), (vc - s(3)) / tau,
        (omegac - s(4)) / tau;
    return d;
  };
  return rk4(f, x0, h, 20000);
}

/// a − b wrapped to [−π, π].
inline double angleBetween(double a, double b) { return std::remainder(a - b, 2.0 * kPi); }

/// The key of the ParameterError that @p make throws, "" if none.
template <typename Make>
std::string refusedKey(Make make) {
  try {
    make();
  } catch (const ParameterError& e) {
    return e.key();
  }
  return "";
}

}  // namespace testing
}  // namespace projection_collision_avoidance
