/// Validation of controller parameters: every class of invalid parameter is refused with its
/// key, and the derived quantities (Gamma, bounds, gains) are right.

#include <functional>
#include <limits>
#include <random>
#include <type_traits>

#include <Eigen/Eigenvalues>
#include <gtest/gtest.h>

#include "projection_collision_avoidance/core/ControllerDesign.hpp"
#include "projection_collision_avoidance/core/LinearAlgebra.hpp"
#include "projection_collision_avoidance/core/ParameterError.hpp"

#include "EigenTestHelpers.hpp"
#include "TestScenarios.hpp"

namespace projection_collision_avoidance {
namespace {

using testing::paperParameters;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

/// Expects create() to refuse the parameters with @p key, and the message to contain @p text.
void expectRefused(const std::function<void(ControllerParameters&)>& change, const std::string& key,
                   const std::string& text = "") {
  ControllerParameters p = paperParameters();
  change(p);
  try {
    ControllerDesign::create(p);
    ADD_FAILURE() << "accepted; expected a ParameterError for " << key;
  } catch (const ParameterError& error) {
    EXPECT_EQ(error.key(), key) << error.what();
    EXPECT_NE(std::string(error.what()).find(text), std::string::npos) << error.what();
    EXPECT_EQ(std::string(error.what()).rfind(key + ": ", 0), 0u) << error.what();
  }
}

// A design exists only validated: create() is the one way to make one.
static_assert(!std::is_default_constructible_v<ControllerDesign>,
              "ControllerDesign must only be made by ControllerDesign::create()");

TEST(ControllerDesign, AcceptsThePapersParameters) {
  const ControllerDesign design = ControllerDesign::create(paperParameters());
  EXPECT_DOUBLE_EQ(design.xi_max, 4.0);
  EXPECT_DOUBLE_EQ(design.perimeter, 1.0);
  EXPECT_NEAR(design.xi_soft, 4.0 / std::sqrt(1.2), 1e-12);
  EXPECT_DOUBLE_EQ(design.period, 0.01);
  EXPECT_MATRIX_NEAR(design.closed_loop, (Eigen::Matrix2d() << 0, 1, -1, -1.4).finished(), 1e-15);
}

TEST(ControllerDesign, GammaSolvesTheLyapunovEquation) {
  const ControllerDesign design = ControllerDesign::create(paperParameters());
  const Eigen::MatrixXd& F = design.estimator_matrix;
  const Eigen::MatrixXd residual =
      design.gamma * F + F.transpose() * design.gamma + design.parameters.lyapunov_weight;
  EXPECT_LT(residual.norm(), 1e-12);
  EXPECT_MATRIX_NEAR(design.gamma, Eigen::MatrixXd(design.gamma.transpose()), 0.0);
  EXPECT_GT(Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(design.gamma).eigenvalues().minCoeff(),
            0.0);
  EXPECT_MATRIX_NEAR(Eigen::MatrixXd(design.gamma * design.gamma_inverse),
                     Eigen::MatrixXd::Identity(2, 2), 1e-12);
}

TEST(LinearAlgebra, LyapunovSolverOnRandomStableMatrices) {
  std::mt19937 rng(7);
  for (int trial = 0; trial < 200; ++trial) {
    const int n = 1 + trial % 12;
    Eigen::MatrixXd F = testing::randomVector(rng, n * n).reshaped(n, n);
    // Shift the spectrum into the left half plane.
    const double abscissa = eigenvalues(F).real().maxCoeff();
    F -= (abscissa + 0.5) * Eigen::MatrixXd::Identity(n, n);
    ASSERT_TRUE(isHurwitz(F));
    const Eigen::MatrixXd Q = testing::randomSpd(rng, n, 0.1, 10.0);
    double residual = 1.0;
    const Eigen::MatrixXd gamma = solveContinuousLyapunov(F, Q, &residual);
    EXPECT_LT(residual, 1e-9) << "n=" << n;
    EXPECT_LT((gamma * F + F.transpose() * gamma + Q).norm() / Q.norm(), 1e-9);
  }
}

TEST(ControllerDesign, PolePlacementGainsForDoubleIntegrators) {
  EXPECT_MATRIX_NEAR(doubleIntegratorGain(Eigen::VectorXd::Constant(1, 1.0),
                                          Eigen::VectorXd::Constant(1, 0.7), "g"),
                     Eigen::RowVector2d(1.0, 1.4), 1e-15);
  const Eigen::MatrixXd G =
      doubleIntegratorGain(Eigen::Vector2d(2.0, 3.0), Eigen::Vector2d(0.5, 1.0), "g");
  ControllerParameters p = paperParameters();
  p.model = makeDoubleIntegrator(2);
  const Eigen::MatrixXd closed = p.model.A - p.model.B * G;
  // Poles of s^2 + 2 zeta omega s + omega^2: -1 +- 1.732i and -3 (double).
  const Eigen::VectorXcd poles = eigenvalues(closed);
  for (Eigen::Index i = 0; i < poles.size(); ++i) {
    const std::complex<double> s = poles(i);
    const double axis0 = std::abs(s * s + 2.0 * s + 4.0);
    const double axis1 = std::abs(s * s + 6.0 * s + 9.0);
    EXPECT_LT(std::min(axis0, axis1), 1e-6) << s;
  }
  EXPECT_THROW(doubleIntegratorGain(Eigen::Vector2d(1.0, -1.0), Eigen::Vector2d(1.0, 1.0), "g"),
               ParameterError);
  EXPECT_THROW(doubleIntegratorGain(Eigen::Vector2d(1.0, 1.0), Eigen::Vector3d(1.0, 1.0, 1.0), "g"),
               ParameterError);
}

TEST(ControllerDesign, RefusesAlphaOutsideTheUnitInterval) {
  expectRefused([](auto& p) { p.alpha = -0.1; }, "controller.alpha", "[0, 1)");
  expectRefused([](auto& p) { p.alpha = 1.0; }, "controller.alpha", "[0, 1)");
  expectRefused([](auto& p) { p.alpha = kNaN; }, "controller.alpha", "finite");
}

TEST(ControllerDesign, RefusesNonPositiveEpsilon) {
  expectRefused([](auto& p) { p.epsilon = 0.0; }, "controller.epsilon", "positive");
  expectRefused([](auto& p) { p.epsilon = -1.0; }, "controller.epsilon", "positive");
  expectRefused([](auto& p) { p.epsilon = kInf; }, "controller.epsilon", "finite");
}

TEST(ControllerDesign, RefusesSeparationOutsideTheKernelOfA) {
  expectRefused([](auto& p) { p.separation = Eigen::Vector2d(5.0, 0.5); }, "controller.separation",
                "ker(A)");
  expectRefused([](auto& p) { p.separation = Eigen::Vector2d::Zero(); }, "controller.separation",
                "non-zero");
}

TEST(ControllerDesign, RefusesWrongSizes) {
  expectRefused([](auto& p) { p.separation = Eigen::Vector3d(5.0, 0.0, 0.0); },
                "controller.separation", "3");
  expectRefused([](auto& p) { p.baseline_gain = Eigen::Matrix2d::Identity(); },
                "controller.baseline.gain", "1x2");
  expectRefused([](auto& p) { p.estimator_gain = Eigen::RowVector2d(1.0, 1.0); },
                "controller.estimator.gain", "2x2");
  expectRefused([](auto& p) { p.lyapunov_weight = Eigen::Matrix3d::Identity(); },
                "controller.estimator.lyapunov_weight", "2x2");
  expectRefused([](auto& p) { p.tracker_gain = Eigen::Vector2d(10.0, 5.0); },
                "controller.tracker.gain", "1x2");
  expectRefused([](auto& p) { p.reference_gain = Eigen::MatrixXd::Zero(1, 3); },
                "controller.tracker.reference_gain", "1x2");
  expectRefused([](auto& p) { p.model.C = Eigen::MatrixXd::Identity(2, 3); }, "model.C", "2x2");
  expectRefused([](auto& p) { p.model.B = Eigen::MatrixXd::Zero(3, 1); }, "model.B", "2x1");
  expectRefused([](auto& p) { p.model.A = Eigen::MatrixXd::Zero(2, 3); }, "model.A", "2x2");
  expectRefused([](auto& p) { p.model.A = Eigen::MatrixXd::Zero(13, 13); }, "model.A", "1 to 12");
}

TEST(ControllerDesign, RefusesNonFiniteEntries) {
  expectRefused([](auto& p) { p.baseline_gain(0, 1) = kNaN; }, "controller.baseline.gain",
                "non-finite");
  expectRefused([](auto& p) { p.estimator_gain(1, 0) = kInf; }, "controller.estimator.gain",
                "non-finite");
  expectRefused([](auto& p) { p.lyapunov_weight(0, 0) = kNaN; },
                "controller.estimator.lyapunov_weight", "non-finite");
  expectRefused([](auto& p) { p.tracker_gain(0, 0) = -kInf; }, "controller.tracker.gain",
                "non-finite");
  expectRefused([](auto& p) { p.separation(1) = kNaN; }, "controller.separation", "non-finite");
  expectRefused([](auto& p) { p.model.A(0, 0) = kNaN; }, "model.A", "non-finite");
  expectRefused([](auto& p) { p.control_rate = kNaN; }, "controller.control_rate", "finite");
}

TEST(ControllerDesign, RefusesNonHurwitzClosedLoops) {
  // G = 0: A_c = A has a double eigenvalue at 0.
  expectRefused([](auto& p) { p.baseline_gain.setZero(); }, "controller.baseline.gain",
                "A_c = A - B G C is not Hurwitz; its eigenvalues are [");
  expectRefused([](auto& p) { p.baseline_gain << 1.0, -1.0; }, "controller.baseline.gain",
                "eigenvalues");
  expectRefused([](auto& p) { p.estimator_gain = 5.0 * Eigen::Matrix2d::Identity(); },
                "controller.estimator.gain", "A_c + L C is not Hurwitz");
  expectRefused([](auto& p) { p.tracker_gain << -10.0, -5.0; }, "controller.tracker.gain",
                "A_c - B G_e C is not Hurwitz");
}

TEST(ControllerDesign, ADisabledTrackerNeedsNoStableTrackerGain) {
  ControllerParameters p = paperParameters();
  p.tracker_enabled = false;
  p.tracker_gain << -10.0, -5.0;
  EXPECT_NO_THROW(ControllerDesign::create(p));
}

TEST(ControllerDesign, RefusesABadLyapunovWeight) {
  expectRefused([](auto& p) { p.lyapunov_weight << 1.0, 0.5, 0.0, 1.0; },
                "controller.estimator.lyapunov_weight", "symmetric");
  expectRefused([](auto& p) { p.lyapunov_weight << 1.0, 2.0, 2.0, 1.0; },
                "controller.estimator.lyapunov_weight", "positive definite");
  expectRefused([](auto& p) { p.lyapunov_weight.setZero(); },
                "controller.estimator.lyapunov_weight", "positive definite");
}

TEST(ControllerDesign, RefusesANonPositiveAccelerationLimit) {
  expectRefused([](auto& p) { p.acceleration_limit = 0.0; }, "controller.acceleration_limit",
                "positive");
  expectRefused([](auto& p) { p.acceleration_limit = -1.0; }, "controller.acceleration_limit");
  expectRefused([](auto& p) { p.acceleration_limit = kNaN; }, "controller.acceleration_limit");
  ControllerParameters p = paperParameters();
  p.acceleration_limit = kInf;  // no bound
  EXPECT_NO_THROW(ControllerDesign::create(p));
}

TEST(ControllerDesign, RefusesBadRatesAndSubsteps) {
  expectRefused([](auto& p) { p.control_rate = 0.0; }, "controller.control_rate", "positive");
  expectRefused([](auto& p) { p.control_rate = -100.0; }, "controller.control_rate", "positive");
  expectRefused([](auto& p) { p.estimator_substeps = 0; }, "controller.estimator.substeps");
  expectRefused([](auto& p) { p.estimator_substeps = 100000; }, "controller.estimator.substeps");
}

// Explicit RK4 of the estimator is stable only while |R(h lambda)| <= 1 for the eigenvalues of
// A_c + L C; L = -500 I at 100 Hz puts h lambda near -5, beyond RK4's interval [-2.79, 0].
TEST(ControllerDesign, RefusesEstimatorSubstepsThatRk4CannotIntegrate) {
  expectRefused([](auto& p) { p.estimator_gain = -500.0 * Eigen::Matrix2d::Identity(); },
                "controller.estimator.substeps", "use substeps >= 2");
  ControllerParameters p = testing::paperParameters();
  p.estimator_gain = -500.0 * Eigen::Matrix2d::Identity();
  p.estimator_substeps = 2;
  EXPECT_NO_THROW(ControllerDesign::create(p));
  // h lambda near -1e6 at 1 Hz: not even 1000 substeps are enough; the rate is named.
  expectRefused(
      [](auto& q) {
        q.estimator_gain = -1e6 * Eigen::Matrix2d::Identity();
        q.control_rate = 1.0;
      },
      "controller.control_rate", "no substeps up to 1000");
}

TEST(ControllerDesign, AcceptsAGeneralLinearModel) {
  // A damped oscillator with only its position measured: x = [p, v], y = p.
  ControllerParameters p = paperParameters();
  p.model.A << 0.0, 1.0, -1.0, -0.1;
  p.model.C = Eigen::RowVector2d(1.0, 0.0);
  p.model.double_integrator_axes = 0;
  p.separation = Eigen::Vector2d(0.0, 0.0);
  expectRefused([&](auto& q) { q = p; }, "controller.separation", "non-zero");
  // A has a trivial kernel here, so no separation is admissible: the check says so.
  p.separation = Eigen::Vector2d(1.0, 0.0);
  expectRefused([&](auto& q) { q = p; }, "controller.separation", "ker(A)");
  // With an integrator in the model, d = [1, 0] is in ker(A).
  p.model.A << 0.0, 1.0, 0.0, -0.1;
  p.baseline_gain = Eigen::MatrixXd::Constant(1, 1, 2.0);
  p.estimator_gain = Eigen::Vector2d(-4.0, -4.0);
  p.tracker_gain = Eigen::MatrixXd::Constant(1, 1, 1.0);
  p.reference_gain = Eigen::MatrixXd::Zero(1, 1);
  const ControllerDesign design = ControllerDesign::create(p);
  EXPECT_TRUE(isHurwitz(design.estimator_matrix));
  EXPECT_MATRIX_NEAR(design.output_pseudoinverse, Eigen::Vector2d(1.0, 0.0), 1e-12);
}

}  // namespace
}  // namespace projection_collision_avoidance
