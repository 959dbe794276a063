#pragma once

/// @file
/// Eigen-aware gtest assertions that print both operands on failure, and random generators
/// (defined in EigenTestHelpers.cpp).

#include <random>
#include <sstream>

#include <Eigen/Core>
#include <Eigen/LU>
#include <gtest/gtest.h>

namespace projection_collision_avoidance {
namespace testing {

template <typename A, typename B>
::testing::AssertionResult matricesNear(const char* a_expr, const char* b_expr, const char*,
                                        const Eigen::MatrixBase<A>& a,
                                        const Eigen::MatrixBase<B>& b, double tolerance) {
  // Two empty matrices of one shape are equal (maxCoeff() of an empty one is undefined).
  if (a.rows() == b.rows() && a.cols() == b.cols() &&
      (a.size() == 0 || (a - b).cwiseAbs().maxCoeff() <= tolerance)) {
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

/// Random symmetric positive definite n x n matrix with eigenvalues in [low, high]
/// (EigenTestHelpers.cpp: its QR decomposition is compiled once, not in every test).
Eigen::MatrixXd randomSpd(std::mt19937& rng, int n, double low, double high);

/// A vector of n independent normal entries of standard deviation @p scale.
Eigen::VectorXd randomVector(std::mt19937& rng, int n, double scale = 1.0);

/// A random direction scaled to @p radius.
Eigen::VectorXd randomOnSphere(std::mt19937& rng, int n, double radius);

}  // namespace testing
}  // namespace projection_collision_avoidance

#define EXPECT_MATRIX_NEAR(a, b, tolerance) \
  EXPECT_PRED_FORMAT3(::projection_collision_avoidance::testing::matricesNear, a, b, tolerance)
#define ASSERT_MATRIX_NEAR(a, b, tolerance) \
  ASSERT_PRED_FORMAT3(::projection_collision_avoidance::testing::matricesNear, a, b, tolerance)
