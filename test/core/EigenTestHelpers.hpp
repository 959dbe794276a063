#pragma once

/// @file
/// Eigen-aware gtest assertions that print both operands on failure, and random generators.

#include <random>
#include <sstream>

#include <Eigen/Core>
#include <Eigen/LU>
#include <Eigen/QR>
#include <gtest/gtest.h>

namespace projection_collision_avoidance {
namespace testing {

template <typename A, typename B>
::testing::AssertionResult matricesNear(const char* a_expr, const char* b_expr, const char*,
                                        const Eigen::MatrixBase<A>& a,
                                        const Eigen::MatrixBase<B>& b, double tolerance) {
  if (a.rows() == b.rows() && a.cols() == b.cols() &&
      ((a - b).cwiseAbs().maxCoeff() <= tolerance)) {
    return ::testing::AssertionSuccess();
  }
  std::ostringstream message;
  message << a_expr << " and " << b_expr << " differ by more than " << tolerance << "\n"
          << a_expr << " =\n"
          << a << "\n"
          << b_expr << " =\n"
          << b;
  return ::testing::AssertionFailure() << message.str();
}

/// Random symmetric positive definite n x n matrix with eigenvalues in [low, high].
inline Eigen::MatrixXd randomSpd(std::mt19937& rng, int n, double low, double high) {
  std::normal_distribution<double> normal;
  std::uniform_real_distribution<double> uniform(low, high);
  Eigen::MatrixXd M(n, n);
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) {
      M(i, j) = normal(rng);
    }
  }
  const Eigen::MatrixXd Q = Eigen::HouseholderQR<Eigen::MatrixXd>(M).householderQ();
  Eigen::VectorXd values(n);
  for (int i = 0; i < n; ++i) {
    values(i) = uniform(rng);
  }
  return Q * values.asDiagonal() * Q.transpose();
}

inline Eigen::VectorXd randomVector(std::mt19937& rng, int n, double scale = 1.0) {
  std::normal_distribution<double> normal(0.0, scale);
  Eigen::VectorXd v(n);
  for (int i = 0; i < n; ++i) {
    v(i) = normal(rng);
  }
  return v;
}

/// A random direction scaled to @p radius.
inline Eigen::VectorXd randomOnSphere(std::mt19937& rng, int n, double radius) {
  Eigen::VectorXd v = randomVector(rng, n);
  return radius * v / v.norm();
}

}  // namespace testing
}  // namespace projection_collision_avoidance

#define EXPECT_MATRIX_NEAR(a, b, tolerance) \
  EXPECT_PRED_FORMAT3(::projection_collision_avoidance::testing::matricesNear, a, b, tolerance)
#define ASSERT_MATRIX_NEAR(a, b, tolerance) \
  ASSERT_PRED_FORMAT3(::projection_collision_avoidance::testing::matricesNear, a, b, tolerance)
