/// Properties of the Gamma-weighted projection operator (doc/math.md) against the literal
/// reading of the paper's eqs. (12)/(15), and the invariance of Omega_1 under the discretised
/// estimator.

#include <random>

#include <gtest/gtest.h>

#include "projection_collision_avoidance/core/BallConstraint.hpp"
#include "projection_collision_avoidance/core/CollisionFreeEstimator.hpp"
#include "projection_collision_avoidance/core/ControllerDesign.hpp"
#include "projection_collision_avoidance/core/ProjectionOperator.hpp"

#include "EigenTestHelpers.hpp"
#include "TestScenarios.hpp"

namespace projection_collision_avoidance {
namespace {

using testing::randomOnSphere;
using testing::randomSpd;
using testing::randomVector;

constexpr double kXiMax = 4.0;
constexpr double kEpsilon = 0.2;

/// The paper's text taken literally: Gamma^-1 Proj(xi_hat, Gamma h) with the unweighted
/// operator (7) (condition on the field, as Lavretsky & Wise have it).
Eigen::VectorXd literalPaperDrift(const BallConstraint& c, const Eigen::VectorXd& x,
                                  const Eigen::VectorXd& h, const Eigen::MatrixXd& gamma) {
  const Eigen::VectorXd g = gamma * h;
  const Eigen::VectorXd grad = c.gradient(x);
  const double f = c.value(x);
  Eigen::VectorXd projected = g;
  if (f > 0.0 && grad.dot(g) > 0.0) {
    projected = g - f * grad * grad.dot(g) / grad.squaredNorm();
  }
  return gamma.inverse() * projected;
}

// Points on and beyond the boundary (f >= 1): the projected field never points outward.
TEST(ProjectionOperator, NeverPointsOutwardOnOrBeyondTheBoundary) {
  std::mt19937 rng(1);
  const BallConstraint ball(kXiMax, kEpsilon);
  std::uniform_real_distribution<double> beyond(1.0, 1.5);
  int active = 0;
  for (int trial = 0; trial < 20000; ++trial) {
    const int n = 1 + trial % 6;
    const Eigen::MatrixXd gamma = randomSpd(rng, n, 0.01, 100.0);
    const Eigen::MatrixXd gamma_inverse = gamma.inverse();
    const double radius = (trial % 2 == 0) ? kXiMax : kXiMax * beyond(rng);
    const Eigen::VectorXd x = randomOnSphere(rng, n, radius);
    const Eigen::VectorXd h = randomVector(rng, n, 10.0);
    ASSERT_GE(ball.value(x), 1.0 - 1e-12);
    bool was_active = false;
    const Eigen::VectorXd rate = projectDrift(ball, x, h, gamma_inverse, &was_active);
    active += was_active ? 1 : 0;
    const double outward = ball.gradient(x).dot(rate);
    // On the sphere the outward rate is zero up to rounding; beyond it, strictly inward.
    ASSERT_LE(outward, 1e-9 * ball.gradient(x).norm() * h.norm())
        << "n=" << n << " f=" << ball.value(x) << "\nGamma=\n"
        << gamma << "\nx=" << x.transpose() << "\nh=" << h.transpose();
  }
  EXPECT_GT(active, 5000);  // the test exercised the projection, not only the pass-through
}

/// Trials of each LyapunovInequality* test below.
constexpr int kLyapunovTrials = 20000;
/// The least number of those trials in which the projection must act (change the drift) for the
/// test to count: with xi_hat at f > 0 and h drawn symmetrically, grad_f^T h > 0 in about half of
/// them (measured: 10056 of 20000 on or beyond the hard bound, 9909 of 20000 in the band, with
/// the seeds below). A test whose trials all passed the drift through would check nothing.
constexpr int kMinActiveLyapunovTrials = 8000;

/// The projected drift of one trial, checked to equal h when the projection did not act and to
/// differ from it when it did; @p active_count counts the latter.
Eigen::VectorXd projectAndCount(const BallConstraint& ball, const Eigen::VectorXd& x,
                                const Eigen::VectorXd& h, const Eigen::MatrixXd& gamma,
                                int* active_count, bool* active) {
  *active = false;
  const Eigen::VectorXd rate = projectDrift(ball, x, h, Eigen::MatrixXd(gamma.inverse()), active);
  if (*active) {
    EXPECT_GT((rate - h).norm(), 0.0) << "reported active but the drift is unchanged";
    ++*active_count;
  } else {
    EXPECT_MATRIX_NEAR(rate, h, 0.0);
  }
  return rate;
}

// Theorem 3.1's inequality (xi_hat - xi)^T Gamma (xi_hat' - h) <= 0 for xi inside Omega_1 and
// xi_hat on or beyond the boundary. Where the projection does not act xi_hat' = h and the
// inequality holds trivially (0 <= 0), so only the trials in which it acts count.
TEST(ProjectionOperator, LyapunovInequalityForXiInsideTheHardBound) {
  std::mt19937 rng(2);
  const BallConstraint ball(kXiMax, kEpsilon);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  int active = 0;
  for (int trial = 0; trial < kLyapunovTrials; ++trial) {
    const int n = 1 + trial % 6;
    const Eigen::MatrixXd gamma = randomSpd(rng, n, 0.01, 100.0);
    const Eigen::VectorXd x = randomOnSphere(rng, n, kXiMax * (1.0 + 0.5 * unit(rng)));
    const Eigen::VectorXd xi = randomOnSphere(rng, n, kXiMax * unit(rng));
    const Eigen::VectorXd h = randomVector(rng, n, 10.0);
    bool acted = false;
    const Eigen::VectorXd rate = projectAndCount(ball, x, h, gamma, &active, &acted);
    if (!acted) {
      continue;
    }
    const double value = (x - xi).dot(gamma * (rate - h));
    ASSERT_LE(value, 1e-9 * (1.0 + gamma.norm() * h.norm() * x.norm()))
        << "trial " << trial << " (active trial " << active << "), n=" << n
        << " f=" << ball.value(x);
  }
  RecordProperty("active_trials", active);
  EXPECT_GE(active, kMinActiveLyapunovTrials)
      << "the projection acted in " << active << " of " << kLyapunovTrials << " trials";
}

// Inside the soft band (0 < f < 1) the inequality holds for every xi in Omega_0 (Lavretsky &
// Wise's hypothesis), and more generally whenever ||xi|| <= ||xi_hat||. Only the trials in which
// the projection acts count, as above.
TEST(ProjectionOperator, LyapunovInequalityInTheBandForXiInsideTheSoftBound) {
  std::mt19937 rng(3);
  const BallConstraint ball(kXiMax, kEpsilon);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  int active = 0;
  for (int trial = 0; trial < kLyapunovTrials; ++trial) {
    const int n = 1 + trial % 6;
    const Eigen::MatrixXd gamma = randomSpd(rng, n, 0.01, 100.0);
    const double r = ball.softRadius() + (kXiMax - ball.softRadius()) * unit(rng);
    const Eigen::VectorXd x = randomOnSphere(rng, n, r);
    const Eigen::VectorXd xi = randomOnSphere(rng, n, r * unit(rng));
    const Eigen::VectorXd h = randomVector(rng, n, 10.0);
    bool acted = false;
    const Eigen::VectorXd rate = projectAndCount(ball, x, h, gamma, &active, &acted);
    if (!acted) {
      continue;
    }
    ASSERT_LE((x - xi).dot(gamma * (rate - h)), 1e-9 * (1.0 + gamma.norm() * h.norm() * x.norm()))
        << "trial " << trial << " (active trial " << active << "), n=" << n
        << " f=" << ball.value(x);
  }
  RecordProperty("active_trials", active);
  EXPECT_GE(active, kMinActiveLyapunovTrials)
      << "the projection acted in " << active << " of " << kLyapunovTrials << " trials";
}

// ... but not for every xi in Omega_1: with xi_hat in the band and xi farther out along the same
// direction, the removed term has the wrong sign. Theorem 3.1 therefore needs xi in Omega_0 (or
// ||xi|| <= ||xi_hat||) while the projection acts; the test pins this down.
TEST(ProjectionOperator, LyapunovInequalityCanFailInTheBandForXiBetweenTheBounds) {
  const BallConstraint ball(kXiMax, kEpsilon);
  const Eigen::MatrixXd gamma = Eigen::MatrixXd::Identity(2, 2);
  const Eigen::VectorXd x = Eigen::Vector2d(3.9, 0.0);   // 0 < f < 1
  const Eigen::VectorXd xi = Eigen::Vector2d(4.0, 0.0);  // on the hard bound
  const Eigen::VectorXd h = Eigen::Vector2d(1.0, 0.0);   // pointing outward
  ASSERT_GT(ball.value(x), 0.0);
  ASSERT_LT(ball.value(x), 1.0);
  bool active = false;
  const Eigen::VectorXd rate = projectDrift(ball, x, h, gamma, &active);
  ASSERT_TRUE(active) << "the projection must act for the counterexample to mean anything";
  ASSERT_GT((rate - h).norm(), 0.0);
  EXPECT_GT((x - xi).dot(gamma * (rate - h)), 0.0);
}

// The literal Gamma^-1 Proj(xi_hat, Gamma h) lets the field point out of Omega_1 on its
// boundary when Gamma is not a multiple of I: it fails the first property.
TEST(ProjectionOperator, LiteralPaperFormPointsOutwardOnTheBoundary) {
  std::mt19937 rng(4);
  const BallConstraint ball(kXiMax, kEpsilon);
  int outward_cases = 0;
  double worst = 0.0;
  for (int trial = 0; trial < 2000; ++trial) {
    const Eigen::MatrixXd gamma = randomSpd(rng, 2, 0.1, 10.0);
    const Eigen::VectorXd x = randomOnSphere(rng, 2, kXiMax);
    const Eigen::VectorXd h = randomVector(rng, 2, 10.0);
    const Eigen::VectorXd rate = literalPaperDrift(ball, x, h, gamma);
    const double outward = ball.gradient(x).dot(rate) / ball.gradient(x).norm();
    if (outward > 1e-6) {
      ++outward_cases;
    }
    worst = std::max(worst, outward);
  }
  EXPECT_GT(outward_cases, 100) << "largest outward rate " << worst << " m/s";
}

// With Gamma = c I the literal form and the weighted form agree.
TEST(ProjectionOperator, LiteralAndWeightedFormsAgreeForScalarGamma) {
  std::mt19937 rng(5);
  const BallConstraint ball(kXiMax, kEpsilon);
  for (int trial = 0; trial < 500; ++trial) {
    const Eigen::MatrixXd gamma = 3.7 * Eigen::MatrixXd::Identity(3, 3);
    const Eigen::VectorXd x = randomOnSphere(rng, 3, kXiMax * (0.9 + 0.2 * (trial % 3)));
    const Eigen::VectorXd h = randomVector(rng, 3, 10.0);
    EXPECT_MATRIX_NEAR(projectDrift(ball, x, h, Eigen::MatrixXd(gamma.inverse()), nullptr),
                       literalPaperDrift(ball, x, h, gamma), 1e-10);
  }
}

TEST(ProjectionOperator, PassesTheDriftThroughInsideTheSoftBound) {
  const BallConstraint ball(kXiMax, kEpsilon);
  const Eigen::VectorXd x = Eigen::Vector2d(1.0, 2.0);
  const Eigen::VectorXd h = Eigen::Vector2d(5.0, 7.0);
  bool active = false;
  EXPECT_MATRIX_NEAR(
      projectDrift(ball, x, h, Eigen::MatrixXd(Eigen::Matrix2d::Identity()), &active), h, 0.0);
  EXPECT_FALSE(active);
}

TEST(BallConstraint, LevelSetsAreTheSoftAndHardBalls) {
  const BallConstraint ball(kXiMax, kEpsilon);
  EXPECT_NEAR(ball.value(Eigen::Vector2d(kXiMax, 0.0)), 1.0, 1e-12);
  EXPECT_NEAR(ball.value(Eigen::Vector2d(0.0, ball.softRadius())), 0.0, 1e-12);
  EXPECT_NEAR(ball.softRadius(), kXiMax / std::sqrt(1.0 + kEpsilon), 1e-12);
  // Gradient by central differences.
  const Eigen::Vector3d x(1.0, -2.0, 0.5);
  const Eigen::Vector3d g = ball.gradient(x);
  for (int i = 0; i < 3; ++i) {
    Eigen::Vector3d step = Eigen::Vector3d::Zero();
    step(i) = 1e-6;
    EXPECT_NEAR(g(i), (ball.value(x + step) - ball.value(x - step)) / 2e-6, 1e-6);
  }
}

/// A design with a strongly non-normal A_c + L C (so Gamma is far from c I).
ControllerDesign skewedDesign(int substeps) {
  ControllerParameters p = testing::paperParameters();
  p.estimator_gain = (Eigen::Matrix2d() << -5.0, 3.0, -8.0, -2.0).finished();
  p.lyapunov_weight = (Eigen::Matrix2d() << 1.0, 0.3, 0.3, 4.0).finished();
  p.estimator_substeps = substeps;
  return ControllerDesign::create(p);
}

// The discretised estimator keeps ||xi_hat|| <= xi_max after every period, for measurements far
// outside the bound, and the boundary safeguard removes only RK4's truncation error.
TEST(CollisionFreeEstimator, DiscretisationKeepsTheHardBound) {
  std::mt19937 rng(6);
  for (const int substeps : {1, 4}) {
    const ControllerDesign design = skewedDesign(substeps);
    ASSERT_GT((design.gamma - design.gamma(0, 0) * Eigen::Matrix2d::Identity()).norm(), 0.1);
    CollisionFreeEstimator<DoubleIntegrator1D> estimator(design);
    estimator.reset(Eigen::Vector2d(0.0, design.xi_max));
    double largest_correction = 0.0;
    int active_periods = 0;
    for (int k = 0; k < 20000; ++k) {
      const Eigen::Vector2d y = randomOnSphere(rng, 2, design.xi_max * 3.0);
      const Eigen::Matrix<double, 1, 1> u_a = randomVector(rng, 1, 20.0);
      const EstimatorPeriodReport report =
          estimator.advance(y, u_a, Eigen::Vector2d::Zero(), design.period, substeps);
      ASSERT_LE(estimator.estimate().norm(), design.xi_max) << "period " << k;
      largest_correction = std::max(largest_correction, report.boundary_correction);
      active_periods += report.projection_active ? 1 : 0;
    }
    EXPECT_GT(active_periods, 1000);
    EXPECT_LT(largest_correction, 1e-6 * design.xi_max) << "substeps " << substeps;
  }
}

}  // namespace
}  // namespace projection_collision_avoidance
