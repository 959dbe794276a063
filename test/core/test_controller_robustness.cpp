/// Robustness of the core controller against inputs the theory does not cover: non-finite
/// measurements and leader inputs, finite values so large that the laws overflow, huge gains,
/// and extreme bounds. One test per fix found by test/fuzz/fuzz_follower_controller.cpp (or
/// foreseen in its brief); the contract is in the doxygen of FollowerController::step().

#include <cmath>
#include <limits>
#include <random>

#include <gtest/gtest.h>

#include "projection_collision_avoidance/core/BallConstraint.hpp"
#include "projection_collision_avoidance/core/CollisionFreeEstimator.hpp"
#include "projection_collision_avoidance/core/ControllerDesign.hpp"
#include "projection_collision_avoidance/core/DynamicFollowerController.hpp"
#include "projection_collision_avoidance/core/FollowerController.hpp"

#include "EigenTestHelpers.hpp"
#include "TestScenarios.hpp"

namespace projection_collision_avoidance {
namespace {

using Controller1D = FollowerController<DoubleIntegrator1D>;
using Controller2D = FollowerController<DoubleIntegrator2D>;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kLargest = std::numeric_limits<double>::max();
constexpr double kTiniest = std::numeric_limits<double>::denorm_min();

/// The paper's parameters in 2-D (d = [5, 0, 0, 0]), the same gains on both axes.
ControllerParameters planarParameters() {
  ControllerParameters p;
  p.model = makeDoubleIntegrator(2);
  p.control_rate = 100.0;
  p.separation = (Eigen::VectorXd(4) << 5.0, 0.0, 0.0, 0.0).finished();
  p.alpha = 0.2;
  p.epsilon = 0.2;
  p.baseline_gain = doubleIntegratorGain(Eigen::Vector2d(1.0, 1.0), Eigen::Vector2d(0.7, 0.7), "G");
  p.estimator_gain = -5.0 * Eigen::Matrix4d::Identity();
  p.lyapunov_weight = Eigen::Matrix4d::Identity();
  p.tracker_gain = doubleIntegratorGain(Eigen::Vector2d(3.0, 3.0), Eigen::Vector2d(0.7, 0.7), "Ge");
  p.reference_gain = Eigen::MatrixXd::Zero(2, 4);
  return p;
}

template <typename Status>
void expectFallbackTwin(const Status& a, const Status& b) {
  EXPECT_MATRIX_NEAR(a.command, b.command, 0.0);
  EXPECT_MATRIX_NEAR(a.estimate, b.estimate, 0.0);
  EXPECT_EQ(a.fallback, b.fallback);
  EXPECT_EQ(a.command_saturated, b.command_saturated);
}

// Bug (fuzzer, first seconds): a NaN or infinite y went into G y and the estimator, so the
// command was NaN and the estimate NaN for good (moveIntoBound() does nothing on NaN). Now the
// measurement counts as missing: the tick is the fallback's (step({})), flagged.
TEST(ControllerRobustness, NonFiniteMeasurementRunsTheFallback) {
  const ControllerDesign design = ControllerDesign::create(testing::paperParameters());
  for (const double bad : {kNaN, kInf, -kInf}) {
    Controller1D controller(design);
    Controller1D twin(design);
    for (int k = 0; k < 20; ++k) {
      controller.step({Eigen::Vector2d(3.0, -0.5)});
      twin.step({Eigen::Vector2d(3.0, -0.5)});
    }
    for (int k = 0; k < 5; ++k) {
      const auto& status = controller.step({Eigen::Vector2d(1.0, bad)});
      const auto& expected = twin.step({});
      EXPECT_TRUE(status.measurement_rejected);
      EXPECT_TRUE(status.fallback);
      EXPECT_FALSE(expected.measurement_rejected);
      expectFallbackTwin(status, expected);
      ASSERT_TRUE(controller.estimate().allFinite());
    }
    // The next finite measurement resumes the laws from the predicted estimate.
    const auto& status = controller.step({Eigen::Vector2d(3.0, -0.5)});
    const auto& expected = twin.step({Eigen::Vector2d(3.0, -0.5)});
    EXPECT_FALSE(status.measurement_rejected);
    EXPECT_FALSE(status.fallback);
    EXPECT_MATRIX_NEAR(status.command, expected.command, 0.0);
    EXPECT_MATRIX_NEAR(controller.estimate(), twin.estimate(), 0.0);
  }
}

TEST(ControllerRobustness, NonFiniteFirstMeasurementLeavesTheControllerUninitialised) {
  const ControllerDesign design = ControllerDesign::create(testing::paperParameters());
  DynamicFollowerController controller(design);
  const auto& status = controller.step({Eigen::Vector2d(kNaN, 0.0)});
  EXPECT_TRUE(status.measurement_rejected);
  EXPECT_TRUE(status.fallback);
  EXPECT_TRUE(status.command.isZero());  // the fallback from the zero estimate
  // The first finite measurement initialises the estimate from itself, as without the NaN.
  controller.step({Eigen::Vector2d(2.0, 0.5)});
  DynamicFollowerController fresh(design);
  fresh.step({Eigen::Vector2d(2.0, 0.5)});
  EXPECT_MATRIX_NEAR(controller.estimate(), fresh.estimate(), 0.0);
  EXPECT_FALSE(controller.status().measurement_rejected);
}

// A NaN u_1 shared into the command and the estimator would poison both: it is taken as unknown.
TEST(ControllerRobustness, NonFiniteLeaderInputIsTakenAsUnknown) {
  ControllerParameters p = testing::paperParameters();
  p.leader_input_in_command = true;
  p.leader_input_in_estimator = true;
  const ControllerDesign design = ControllerDesign::create(p);
  DynamicFollowerController controller(design);
  DynamicFollowerController twin(design);
  const Eigen::Vector2d y(1.5, -0.3);
  const Eigen::VectorXd bad = Eigen::VectorXd::Constant(1, kNaN);
  for (int k = 0; k < 10; ++k) {
    const DynamicFollowerStatus& status = controller.step({y, bad});
    const DynamicFollowerStatus& expected = twin.step({y});
    EXPECT_TRUE(status.leader_input_rejected);
    EXPECT_FALSE(status.measurement_rejected);
    EXPECT_MATRIX_NEAR(status.command, expected.command, 0.0);
    EXPECT_MATRIX_NEAR(status.feedforward_command, Eigen::VectorXd::Zero(1), 0.0);
  }
  const DynamicFollowerStatus& status = controller.step({std::nullopt, bad});
  EXPECT_TRUE(status.leader_input_rejected);
  EXPECT_MATRIX_NEAR(status.command, twin.step({}).command, 0.0);
  EXPECT_MATRIX_NEAR(controller.estimate(), twin.estimate(), 0.0);
}

// Bug (fuzzer): a finite y near DBL_MAX overflowed G y + u_a to +-inf; the saturation then gave
// inf * (limit / inf) = NaN (or inf without a limit), and the estimator's L y overflowed too.
// Now a command that is not finite is replaced by the fallback's, flagged command_overflow.
TEST(ControllerRobustness, HugeFiniteMeasurementGivesTheFallbackCommand) {
  for (const double limit : {kInf, 2.0}) {
    ControllerParameters p = testing::paperParameters();
    p.acceleration_limit = limit;
    const ControllerDesign design = ControllerDesign::create(p);
    Controller1D controller(design);
    Controller1D twin(design);
    controller.step({Eigen::Vector2d(3.0, 1.0)});
    twin.step({Eigen::Vector2d(3.0, 1.0)});
    const auto& status = controller.step({Eigen::Vector2d(kLargest, -kLargest)});
    const auto& expected = twin.step({});
    EXPECT_TRUE(status.command_overflow);
    EXPECT_TRUE(status.fallback);
    EXPECT_FALSE(status.measurement_rejected);
    expectFallbackTwin(status, expected);
    EXPECT_TRUE(status.command.allFinite());
    EXPECT_LE(euclideanNorm(controller.estimate()), design.xi_max);
    // Back to ordinary values: the laws again.
    EXPECT_FALSE(controller.step({Eigen::Vector2d(3.0, 1.0)}).fallback);
  }
}

// A huge, finite command whose norm overflows (sqrt(inf)) was scaled by limit / inf = 0 to zero
// instead of onto the limit; now its direction is kept.
TEST(ControllerRobustness, SaturationKeepsTheDirectionOfAHugeCommand) {
  ControllerParameters p = planarParameters();
  p.tracker_enabled = false;
  p.acceleration_limit = 2.0;
  p.baseline_gain = doubleIntegratorGain(Eigen::Vector2d(1.0, 1.0), Eigen::Vector2d(0.5, 0.5), "G");
  const ControllerDesign design = ControllerDesign::create(p);
  Controller2D controller(design);
  // G y = [1e308, 1e308]: finite, its norm is not.
  const auto& status = controller.step({Eigen::Vector4d(1e308, 1e308, 0.0, 0.0)});
  EXPECT_FALSE(status.command_overflow);
  EXPECT_TRUE(status.command_saturated);
  EXPECT_MATRIX_NEAR(status.command, Eigen::Vector2d::Constant(std::sqrt(2.0)), 1e-15);
  EXPECT_LE(euclideanNorm(status.command), 2.0);
}

// K_f xi_hat overflows for a huge fallback gain (which create() accepts): u_ff alone.
TEST(ControllerRobustness, HugeFallbackGainGivesTheFeedforwardCommand) {
  ControllerParameters p = testing::paperParameters();
  p.fallback_gain = Eigen::RowVector2d(0.0, 1e308);
  p.leader_input_in_command = true;
  const ControllerDesign design = ControllerDesign::create(p);
  Controller1D controller(design);
  controller.resetEstimate(Eigen::Vector2d(0.0, 3.0));
  const auto& status = controller.step({std::nullopt, Eigen::Matrix<double, 1, 1>(0.5)});
  EXPECT_TRUE(status.command_overflow);
  EXPECT_DOUBLE_EQ(status.command(0), 0.5);
  EXPECT_EQ(status.fallback_command(0), 0.0);
  EXPECT_TRUE(controller.estimate().allFinite());
}

// L y overflowing inside the estimator (finite laws) made the estimate NaN for good; now the
// substep is discarded and the estimate held.
TEST(ControllerRobustness, EstimatorHoldsTheEstimateWhenItsInputOverflows) {
  const ControllerDesign design = ControllerDesign::create(testing::paperParameters());
  CollisionFreeEstimator<DoubleIntegrator1D> estimator(design);
  estimator.reset(Eigen::Vector2d(1.0, 0.5));
  const Eigen::Vector2d before = estimator.estimate();
  const EstimatorPeriodReport report =
      estimator.advance(Eigen::Vector2d(kLargest, kLargest), Eigen::Matrix<double, 1, 1>(0.0),
                        Eigen::Vector2d::Zero(), design.period, 4);
  EXPECT_TRUE(report.estimate_held);
  EXPECT_MATRIX_NEAR(estimator.estimate(), before, 0.0);
  // A finite drift that overflows within the RK4 stages: the same.
  const EstimatorPeriodReport stages = estimator.predict(Eigen::Vector2d(0.0, 1e307), 1e3, 1);
  EXPECT_TRUE(stages.estimate_held);
  EXPECT_MATRIX_NEAR(estimator.estimate(), before, 0.0);
  const EstimatorPeriodReport ordinary =
      estimator.advance(Eigen::Vector2d(1.0, 0.5), Eigen::Matrix<double, 1, 1>(0.0),
                        Eigen::Vector2d::Zero(), design.period, 4);
  EXPECT_FALSE(ordinary.estimate_held);
}

// A non-finite estimate from outside used to be kept (NaN) by resetEstimate().
TEST(ControllerRobustness, NonFiniteResetEstimateGivesZero) {
  Controller1D controller(ControllerDesign::create(testing::paperParameters()));
  controller.resetEstimate(Eigen::Vector2d(kNaN, 1.0));
  EXPECT_TRUE(controller.estimate().isZero());
  controller.resetEstimate(Eigen::Vector2d(kInf, 1.0));
  EXPECT_TRUE(controller.estimate().isZero());
  EXPECT_TRUE(controller.initialized());
}

// The initial estimate pinv(C) y of a huge y can overflow: it goes on the sphere along y.
TEST(ControllerRobustness, HugeScaledResetLandsOnTheSphere) {
  const ControllerDesign design = ControllerDesign::create(testing::paperParameters());
  CollisionFreeEstimator<DoubleIntegrator1D> estimator(design);
  estimator.reset(Eigen::Vector2d(1.0, 1.0), kLargest);
  EXPECT_TRUE(estimator.estimate().allFinite());
  EXPECT_LE(euclideanNorm(estimator.estimate()), design.xi_max);
  EXPECT_NEAR(estimator.estimate()(0), design.xi_max / std::sqrt(2.0), 1e-12);
  EXPECT_NEAR(estimator.estimate()(1), design.xi_max / std::sqrt(2.0), 1e-12);
  estimator.reset(Eigen::Vector2d(kNaN, 1.0), 2.0);
  EXPECT_TRUE(estimator.estimate().isZero());
}

// Bug (fuzzer): the bound was checked with the fixed-size vector's norm(), and the status copied
// into an Eigen::VectorXd, whose norm() sums in another order, read one ulp above xi_max.
TEST(ControllerRobustness, BoundHoldsInEveryNormEvaluation) {
  ControllerParameters p = planarParameters();
  p.model = makeDoubleIntegrator(3);
  p.separation = (Eigen::VectorXd(6) << 0.3, 0.2, 0.1, 0.0, 0.0, 0.0).finished();
  p.alpha = 0.5;
  p.baseline_gain = doubleIntegratorGain(Eigen::Vector3d::Ones(), Eigen::Vector3d::Ones(), "G");
  p.tracker_gain =
      doubleIntegratorGain(Eigen::Vector3d::Constant(3.0), Eigen::Vector3d::Ones(), "Ge");
  p.estimator_gain = -5.0 * Eigen::MatrixXd::Identity(6, 6);
  p.lyapunov_weight = Eigen::MatrixXd::Identity(6, 6);
  p.reference_gain = Eigen::MatrixXd::Zero(3, 6);
  const ControllerDesign design = ControllerDesign::create(p);
  DynamicFollowerController controller(design);
  std::mt19937 rng(7);
  for (int k = 0; k < 3000; ++k) {
    const Eigen::VectorXd y = testing::randomVector(rng, 6, 5.0);
    controller.step({y});
    const Eigen::VectorXd estimate = controller.estimate();
    ASSERT_LE(estimate.norm(), design.xi_max) << "step " << k;
    ASSERT_LE(std::sqrt(estimate.array().square().sum()), design.xi_max) << "step " << k;
    ASSERT_LE(euclideanNorm(estimate), design.xi_max) << "step " << k;
  }
}

TEST(ControllerRobustness, EuclideanNormNeitherOverflowsNorUnderflows) {
  EXPECT_EQ(euclideanNorm(Eigen::Vector2d(3.0, 4.0)), 5.0);
  EXPECT_DOUBLE_EQ(euclideanNorm(Eigen::Vector2d(3e300, 4e300)), 5e300);
  EXPECT_DOUBLE_EQ(euclideanNorm(Eigen::Vector2d(3e-300, 4e-300)), 5e-300);
  EXPECT_EQ(euclideanNorm(Eigen::Vector2d(kTiniest, 0.0)), kTiniest);
  EXPECT_EQ(euclideanNorm(Eigen::Vector2d(kLargest, kLargest)), kInf);  // beyond DBL_MAX
  EXPECT_EQ(euclideanNorm(Eigen::Vector2d::Zero()), 0.0);
}

// Bug (fuzzer, a 14 s timeout): a subnormal acceleration_limit (6.9e-309) and a command of
// about 1e12: the factor limit / norm was a subnormal with a few significant bits, the scaled
// command up to 1e-4 relative too long, and the loop that shrinks it by one ulp per pass ran for
// about 1e11 passes. Now the vector is normalised first and the shrink step doubles.
TEST(ControllerRobustness, ClampNormReachesEveryRadius) {
  const double subnormal_limit = 0x0.4ffffff009fcap-1022;  // the fuzzer's
  for (const double radius : {2.0, 1e-300, subnormal_limit, 1e-320, kTiniest, 0.0, 1e300}) {
    for (const Eigen::Vector3d& x :
         {Eigen::Vector3d(kLargest, -kLargest, kLargest), Eigen::Vector3d(3.0, -4.0, 12.0),
          Eigen::Vector3d(3e12, -4e12, 12e12), Eigen::Vector3d(kTiniest, kTiniest, kTiniest)}) {
      Eigen::Vector3d clamped = x;
      const double before = clampNorm(clamped, radius);
      ASSERT_TRUE(clamped.allFinite());
      EXPECT_LE(euclideanNorm(clamped), radius) << "radius " << radius;
      if (before > 0.0) {
        EXPECT_GT(before, radius);
        // The direction survives, to the precision the radius leaves.
        const double tolerance = radius >= 1e-300 ? 1e-12 : (radius >= 1e-309 ? 1e-9 : 1.0);
        if (radius >= 1e-309) {
          EXPECT_GE(euclideanNorm(clamped), radius * (1.0 - tolerance)) << "radius " << radius;
        }
        const Eigen::Vector3d direction = (x / x.cwiseAbs().maxCoeff()).normalized();
        if (!clamped.isZero()) {
          EXPECT_MATRIX_NEAR(clamped / euclideanNorm(clamped), direction, tolerance);
        }
      } else {
        EXPECT_MATRIX_NEAR(clamped, x, 0.0);
      }
    }
  }
}

TEST(ControllerRobustness, SubnormalAccelerationLimitSaturatesQuickly) {
  ControllerParameters p = testing::paperParameters();
  p.acceleration_limit = 0x0.4ffffff009fcap-1022;
  const ControllerDesign design = ControllerDesign::create(p);
  Controller1D controller(design);
  const auto& status = controller.step({Eigen::Vector2d(1e12, -3e11)});
  EXPECT_TRUE(status.command_saturated);
  EXPECT_LE(euclideanNorm(status.command), p.acceleration_limit);
  EXPECT_GT(status.command(0), 0.0);
}

// Extreme xi_max (create() accepts any ||d|| > 0): f() was NaN as (0 - 0) * inf or
// (x - inf) * 0; it is now finite or infinite, never NaN.
TEST(ControllerRobustness, ConstraintValueIsNeverNaN) {
  for (const double xi_max : {kTiniest, 1e-200, 4.0, 1e200, kInf}) {
    const BallConstraint ball(xi_max, 0.2);
    for (const Eigen::Vector2d& x :
         {Eigen::Vector2d(0.0, 0.0), Eigen::Vector2d(kTiniest, 0.0), Eigen::Vector2d(1.0, -2.0),
          Eigen::Vector2d(1e200, 1e200), Eigen::Vector2d(kLargest, kLargest)}) {
      EXPECT_FALSE(std::isnan(ball.value(x))) << "xi_max " << xi_max << " x " << x.transpose();
    }
  }
  // Bit for bit the formula (13) where it is fine.
  const BallConstraint ball(4.0, 0.2);
  const double scale = 1.0 / (0.2 * 4.0 * 4.0);
  EXPECT_EQ(ball.value(Eigen::Vector2d(4.0, 0.0)), ((1.0 + 0.2) * 16.0 - 16.0) * scale);
  EXPECT_EQ(ball.value(Eigen::Vector2d(0.0, 0.0)), (0.0 - 16.0) * scale);
  EXPECT_EQ(ball.value(Eigen::Vector2d(1.0, -2.0)), ((1.0 + 0.2) * 5.0 - 16.0) * scale);
}

}  // namespace
}  // namespace projection_collision_avoidance
