/// The command rate limit (controller.jerk_limit): CommandRateLimiter, and the follower's
/// command and estimator under it, in tracking, in the fallback and across changes of mode.

#include <cmath>
#include <limits>
#include <random>
#include <string>

#include <gtest/gtest.h>

#include "projection_collision_avoidance/core/CommandRateLimiter.hpp"
#include "projection_collision_avoidance/core/ControllerDesign.hpp"
#include "projection_collision_avoidance/core/DynamicFollowerController.hpp"
#include "projection_collision_avoidance/core/FollowerController.hpp"
#include "projection_collision_avoidance/core/ParameterError.hpp"
#include "projection_collision_avoidance/scenario/ScenarioLoader.hpp"

#include "EigenTestHelpers.hpp"
#include "TestScenarios.hpp"

namespace projection_collision_avoidance {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
using Controller1D = FollowerController<DoubleIntegrator1D>;
using Controller2D = FollowerController<DoubleIntegrator2D>;
using Vector2 = DoubleIntegrator2D::InputVector;

/// Two double integrators in the plane, d = [3, 4] m, G = [1, 1.4] and G_e = [10, 5] per axis,
/// L = -5 I, Q = I, 100 Hz.
ControllerParameters planarParameters(double jerk_limit, double acceleration_limit) {
  ControllerParameters p;
  p.model = makeDoubleIntegrator(2);
  p.control_rate = 100.0;
  p.separation = Eigen::Vector4d(3.0, 4.0, 0.0, 0.0);
  p.alpha = 0.2;
  p.epsilon = 0.2;
  p.baseline_gain = doubleIntegratorGain(Eigen::Vector2d::Ones(), Eigen::Vector2d::Constant(0.7),
                                         "controller.baseline");
  p.estimator_gain = -5.0 * Eigen::Matrix4d::Identity();
  p.lyapunov_weight = Eigen::Matrix4d::Identity();
  p.tracker_gain = doubleIntegratorGain(Eigen::Vector2d::Constant(std::sqrt(10.0)),
                                        Eigen::Vector2d::Constant(5.0 / (2.0 * std::sqrt(10.0))),
                                        "controller.tracker");
  p.reference_gain = Eigen::MatrixXd::Zero(2, 4);
  p.leader_input_in_command = true;
  p.jerk_limit = jerk_limit;
  p.acceleration_limit = acceleration_limit;
  return p;
}

/// Measurements that jump every 23 ticks, now inside, now far outside the bound (4 m).
class JumpingMeasurement {
 public:
  Eigen::Vector4d next(int k) {
    if (k % 23 == 0) {
      std::uniform_real_distribution<double> position(-7.0, 7.0);
      std::uniform_real_distribution<double> velocity(-3.0, 3.0);
      y_ << position(rng_), position(rng_), velocity(rng_), velocity(rng_);
    }
    return y_;
  }

 private:
  std::mt19937 rng_{20240614};
  Eigen::Vector4d y_ = Eigen::Vector4d::Zero();
};

/// The command before the rate limit: sat(G y + u_a + u_ff) in tracking, sat(u_ff + K_f xi_hat)
/// in the fallback, from the status's parts.
template <typename Status>
Vector2 saturatedTarget(const Status& s, double acceleration_limit) {
  Vector2 target = s.fallback
                       ? Vector2(s.feedforward_command + s.fallback_command)
                       : Vector2(s.baseline_command + s.tracker_command + s.feedforward_command);
  clampNorm(target, acceleration_limit);
  return target;
}

TEST(CommandRateLimiter, LimitsTheChangeInsideTheBall) {
  std::mt19937 rng(7);
  const double radius = 2.0;
  const double period = 0.01;
  CommandRateLimiter<Vector2> limiter(30.0, period, radius, 2);  // r T = 0.3 m/s^2
  int limited = 0;
  for (int k = 0; k < 2000; ++k) {
    const Vector2 previous = limiter.previous();
    Vector2 target = testing::randomVector(rng, 2, 1.5);
    clampNorm(target, radius);
    Vector2 command = target;
    if (limiter.limit(command)) {
      ++limited;
      ASSERT_NEAR(euclideanNorm(command - previous), 0.3, 1e-12);
      // On the segment from the previous command toward the target.
      const Vector2 step = command - previous;
      const Vector2 wanted = target - previous;
      ASSERT_NEAR(step.dot(wanted), step.norm() * wanted.norm(), 1e-12);
    } else {
      ASSERT_EQ(command, target);
    }
    ASSERT_LE(euclideanNorm(command - previous), limiter.maxChange()) << k;
    ASSERT_LE(euclideanNorm(command), radius) << k;
    ASSERT_EQ(limiter.previous(), command);
  }
  EXPECT_GT(limited, 1000);
}

TEST(CommandRateLimiter, AStepLessThanAPeriodAfterTheLastChangesByTheJerkLimitTimesItsTime) {
  std::mt19937 rng(11);
  const double radius = 2.0;
  CommandRateLimiter<Vector2> limiter(30.0, 0.01, radius, 2);  // r T = 0.3 m/s^2
  std::uniform_real_distribution<double> fraction_of(0.0, 1.0);
  int limited = 0;
  for (int k = 0; k < 2000; ++k) {
    const Vector2 previous = limiter.previous();
    Vector2 target = testing::randomVector(rng, 2, 1.5);
    clampNorm(target, radius);
    Vector2 command = target;
    const double fraction = fraction_of(rng);  // Delta t = fraction T
    const double allowed = 30.0 * 0.01 * fraction;
    ASSERT_EQ(limiter.maxChange(fraction), allowed);
    if (limiter.limit(command, fraction)) {
      ++limited;
      ASSERT_NEAR(euclideanNorm(command - previous), allowed, 1e-12) << k;
    } else {
      ASSERT_EQ(command, target) << k;
    }
    ASSERT_LE(euclideanNorm(command - previous), allowed) << k;
    ASSERT_LE(euclideanNorm(command), radius) << k;
  }
  EXPECT_GT(limited, 1000);
  // A whole period or more: r T, bit for bit the limit without a fraction.
  CommandRateLimiter<Vector2> whole(30.0, 0.01, radius, 2);
  CommandRateLimiter<Vector2> late(30.0, 0.01, radius, 2);
  Vector2 a(1.5, -1.0);
  Vector2 b = a;
  Vector2 c = a;
  whole.limit(a);
  late.limit(b, 1.0);
  EXPECT_EQ(a, b);
  late.reset();
  late.limit(c, 7.0);  // two periods late: still r T
  EXPECT_EQ(a, c);
  EXPECT_EQ(whole.maxChange(1.0), whole.maxChange());
  // No time, a negative or a NaN fraction: the command is held.
  for (const double none : {0.0, -0.5, std::nan("")}) {
    Vector2 held(-1.0, 1.0);
    EXPECT_TRUE(whole.limit(held, none)) << none;
    EXPECT_EQ(held, a) << none;
    EXPECT_EQ(whole.maxChange(none), 0.0) << none;
  }
}

TEST(CommandRateLimit, TheControllerLimitsTheChangeToTheStepsFraction) {
  // In tracking and in the fallback, ||u(k) - u(k-1)|| <= r T f for each step's fraction f.
  const double jerk_limit = 20.0;
  const ControllerDesign design = ControllerDesign::create(planarParameters(jerk_limit, 5.0));
  DynamicFollowerController controller(design);
  DynamicFollowerController whole(design);  // f = 1 given explicitly
  DynamicFollowerController plain(design);  // f left at its default
  JumpingMeasurement measurement;
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> fraction_of(0.05, 1.0);
  Eigen::VectorXd previous = Eigen::VectorXd::Zero(2);
  int limited = 0;
  for (int k = 0; k < 1000; ++k) {
    const Eigen::VectorXd y = measurement.next(k);
    DynamicStepInputs inputs;
    if (k % 100 < 70) {
      inputs.measurement.emplace(y);
    }
    const DynamicStepInputs defaults = inputs;
    inputs.period_fraction = fraction_of(rng);
    const DynamicFollowerStatus& s = controller.step(inputs);
    ASSERT_LE(euclideanNorm(s.command - previous),
              jerk_limit * design.period * inputs.period_fraction)
        << k;
    limited += s.command_rate_limited ? 1 : 0;
    previous = s.command;
    inputs.period_fraction = 1.0;
    ASSERT_EQ(whole.step(inputs).command, plain.step(defaults).command) << k;
  }
  EXPECT_GT(limited, 100);
}

TEST(CommandRateLimiter, OverflowingChangeAndOutsidePreviousStayBounded) {
  const double huge = 0.9 * std::numeric_limits<double>::max();
  CommandRateLimiter<Vector2> limiter(1e307, 1.0, kInf, 2);
  limiter.setPrevious(Vector2(huge, -huge));
  Vector2 command(-huge, huge);  // the difference overflows
  EXPECT_TRUE(limiter.limit(command));
  EXPECT_TRUE(command.allFinite());
  EXPECT_LE(euclideanNorm(command - Vector2(huge, -huge)), 1e307);
  EXPECT_GT(euclideanNorm(command - Vector2(huge, -huge)), 0.99e307);

  // A previous command outside the ball (a new, smaller acceleration limit) is moved into it.
  CommandRateLimiter<Vector2> smaller(10.0, 0.01, 1.0, 2);
  smaller.setPrevious(Vector2(3.0, 4.0));
  EXPECT_NEAR(smaller.previous().norm(), 1.0, 1e-15);
  EXPECT_LE(euclideanNorm(smaller.previous()), 1.0);
  smaller.setPrevious(Vector2(std::nan(""), 0.0));
  EXPECT_EQ(smaller.previous(), Vector2::Zero());
}

TEST(CommandRateLimit, FirstCommandStartsFromRest) {
  const ControllerDesign free_design = ControllerDesign::create(planarParameters(kInf, kInf));
  const ControllerDesign design = ControllerDesign::create(planarParameters(20.0, kInf));
  Controller2D free_controller(free_design);
  Controller2D controller(design);
  const Eigen::Vector4d y(2.0, -1.0, 0.5, 0.3);
  const Vector2 wanted = free_controller.step({y}).command;
  ASSERT_GT(wanted.norm(), 0.2);
  const auto& status = controller.step({y});
  EXPECT_TRUE(status.command_rate_limited);
  EXPECT_FALSE(status.command_saturated);
  EXPECT_NEAR(status.command.norm(), 20.0 * design.period, 1e-15);
  EXPECT_MATRIX_NEAR(status.command.normalized(), wanted.normalized(), 1e-14);
  EXPECT_EQ(controller.previousCommand(), status.command);
}

/// Steps a limited and an unlimited controller through tracking (60 ticks) and fallback (40
/// ticks) in turn and checks the limited one's bounds at every tick.
void checkBoundsAcrossModes(double acceleration_limit) {
  SCOPED_TRACE("acceleration_limit " + std::to_string(acceleration_limit));
  const double jerk_limit = 20.0;  // r T = 0.2 m/s^2 at 100 Hz
  const ControllerDesign design =
      ControllerDesign::create(planarParameters(jerk_limit, acceleration_limit));
  Controller2D limited(design);
  Controller2D free(ControllerDesign::create(planarParameters(kInf, acceleration_limit)));
  JumpingMeasurement measurement;
  const Vector2 leader_input(0.4, -0.2);
  const double max_change = jerk_limit * design.period;
  Vector2 previous = Vector2::Zero();
  Vector2 free_previous = Vector2::Zero();
  double free_largest_change = 0.0;
  double free_largest_mode_change = 0.0;
  int rate_limited = 0;
  int saturated = 0;
  int fallback = 0;
  for (int k = 0; k < 3000; ++k) {
    const bool tracking = k % 100 < 60;
    const Eigen::Vector4d y = measurement.next(k);
    const auto& s =
        tracking ? limited.step({y, leader_input}) : limited.step({std::nullopt, leader_input});
    const Vector2 free_command = tracking ? free.step({y, leader_input}).command
                                          : free.step({std::nullopt, leader_input}).command;
    ASSERT_EQ(s.fallback, !tracking);
    ASSERT_LE(euclideanNorm(s.command - previous), max_change) << "tick " << k;
    ASSERT_LE(euclideanNorm(s.command), acceleration_limit) << "tick " << k;
    ASSERT_LE(euclideanNorm(limited.estimate()), design.xi_max) << "tick " << k;
    ASSERT_LE(euclideanNorm(s.estimate), design.xi_max) << "tick " << k;
    const Vector2 target = saturatedTarget(s, acceleration_limit);
    if (s.command_rate_limited) {
      ++rate_limited;
      ASSERT_NEAR(euclideanNorm(s.command - previous), max_change, 1e-12) << "tick " << k;
      const Vector2 step = s.command - previous;
      const Vector2 wanted = target - previous;
      ASSERT_NEAR(step.dot(wanted), step.norm() * wanted.norm(), 1e-9) << "tick " << k;
    } else {
      ASSERT_EQ(s.command, target) << "tick " << k;
    }
    saturated += s.command_saturated ? 1 : 0;
    fallback += s.fallback ? 1 : 0;
    const double free_change = (free_command - free_previous).norm();
    free_largest_change = std::max(free_largest_change, free_change);
    if (k % 100 == 0 || k % 100 == 60) {
      free_largest_mode_change = std::max(free_largest_mode_change, free_change);
    }
    previous = s.command;
    free_previous = free_command;
  }
  EXPECT_GT(rate_limited, 100);
  EXPECT_EQ(fallback, 1200);
  EXPECT_GT(free_largest_change, 5.0 * max_change);       // the limit had work to do ...
  EXPECT_GT(free_largest_mode_change, 5.0 * max_change);  // ... also at the mode changes
  if (std::isfinite(acceleration_limit)) {
    EXPECT_GT(saturated, 0);
  }
}

TEST(CommandRateLimit, BoundHoldsAcrossTrackingAndFallback) {
  checkBoundsAcrossModes(kInf);
  checkBoundsAcrossModes(3.0);
}

/// Without a limit (jerk_limit infinite, or so large it never acts) every tick equals the
/// saturated law with the estimator integrated as before the limit existed, bit for bit.
TEST(CommandRateLimit, WithoutALimitTheLawIsUnchanged) {
  for (const double jerk_limit : {kInf, 1e12}) {
    const ControllerDesign design = ControllerDesign::create(planarParameters(jerk_limit, 3.0));
    Controller2D controller(design);
    CollisionFreeEstimator<DoubleIntegrator2D> estimator(design);
    CollisionFreeTracker<DoubleIntegrator2D> tracker(design);
    // Fixed-size copies, so that the products round as the controller's do.
    const Eigen::Matrix<double, 4, 2> B = design.parameters.model.B;
    const Eigen::Matrix4d C = design.parameters.model.C;
    const Eigen::Matrix<double, 2, 4> G = design.parameters.baseline_gain;
    const Eigen::Matrix<double, 2, 4> Kf = design.fallback_gain;
    const Eigen::Vector4d initial(1.0, -2.0, 0.5, 0.1);
    controller.resetEstimate(initial);
    estimator.reset(initial);
    JumpingMeasurement measurement;
    const Vector2 u1(0.4, -0.2);
    int saturated = 0;
    for (int k = 0; k < 1000; ++k) {
      const bool tracking = k % 100 < 60;
      const Eigen::Vector4d y = measurement.next(k);
      const auto& s = tracking ? controller.step({y, u1}) : controller.step({std::nullopt, u1});
      ASSERT_EQ(s.estimate, estimator.estimate()) << "tick " << k;
      Vector2 command;
      if (tracking) {
        const Vector2 baseline = G * y;
        const Vector2 ua = tracker.command(y, C * estimator.estimate());
        command = baseline + ua + u1;
        const bool clamped = clampNorm(command, 3.0) > 0.0;
        saturated += clamped ? 1 : 0;
        const Vector2 acting = clamped ? Vector2(command - baseline - u1) : ua;
        estimator.advance(y, acting, Eigen::Vector4d::Zero(), design.period, 1);
      } else {
        command = u1 + Kf * estimator.estimate();
        clampNorm(command, 3.0);
        estimator.predict(Eigen::Vector4d(-B * (command - u1)), design.period, 1);
      }
      ASSERT_EQ(s.command, command) << "tick " << k;
      ASSERT_FALSE(s.command_rate_limited);
    }
    EXPECT_EQ(controller.estimate(), estimator.estimate());
    EXPECT_GT(saturated, 0);
  }
}

/// One tracking step of the 1-D controller against RK4 written out: for xi_hat' = F xi_hat + c
/// with F = A_c + L C and c = -L y - B u_act, one step is xi_hat + sum_j T^j / j! F^(j-1) h_0.
TEST(CommandRateLimit, EstimatorIntegratesTheActingCommandInTracking) {
  ControllerParameters p = testing::paperParameters();
  p.jerk_limit = 5.0;  // r T = 0.05 m/s^2
  const ControllerDesign design = ControllerDesign::create(p);
  Controller1D controller(design);
  const Eigen::Vector2d estimate(0.3, -0.2);  // inside Omega_0: no projection
  const Eigen::Vector2d y(1.0, 0.5);
  controller.resetEstimate(estimate);
  const auto& s = controller.step({y});
  ASSERT_TRUE(s.command_rate_limited);
  ASSERT_FALSE(s.projection_active);
  EXPECT_NEAR(std::abs(s.command(0)), 0.05, 1e-15);
  const double acting = s.command(0) - s.baseline_command(0);
  ASSERT_GT(std::abs(acting - s.tracker_command(0)), 1.0);  // the limit changed u_a

  const auto rk4 = [&](double augmentation) {
    const Eigen::Matrix2d F = design.estimator_matrix;
    const Eigen::Vector2d c =
        -p.estimator_gain * y - p.model.B * Eigen::Matrix<double, 1, 1>(augmentation);
    const double T = design.period;
    const Eigen::Vector2d h0 = F * estimate + c;
    const Eigen::Matrix2d series = Eigen::Matrix2d::Identity() + T / 2.0 * F + T * T / 6.0 * F * F +
                                   T * T * T / 24.0 * F * F * F;
    return Eigen::Vector2d(estimate + T * series * h0);
  };
  EXPECT_MATRIX_NEAR(controller.estimate(), rk4(acting), 1e-14);
  EXPECT_GT((controller.estimate() - rk4(s.tracker_command(0))).norm(), 1e-4);
}

TEST(CommandRateLimit, FallbackPredictsWithTheActingCommand) {
  ControllerParameters p = testing::paperParameters();
  p.jerk_limit = 5.0;
  const ControllerDesign design = ControllerDesign::create(p);
  Controller1D controller(design);
  const Eigen::Vector2d xi(0.0, -2.0);  // closing at 2 m/s: K_f xi_hat = -2 m/s^2
  controller.resetEstimate(xi);
  const auto& s = controller.step({});
  ASSERT_TRUE(s.command_rate_limited);
  EXPECT_DOUBLE_EQ(s.fallback_command(0), -2.0);
  EXPECT_NEAR(s.command(0), -0.05, 1e-15);
  // xi' = A xi - B u_2, exact for the held command (RK4 is exact on this quadratic motion).
  const double T = design.period;
  const auto predicted = [&](double u2) {
    return Eigen::Vector2d(xi(0) + xi(1) * T - 0.5 * u2 * T * T, xi(1) - u2 * T);
  };
  EXPECT_MATRIX_NEAR(controller.estimate(), predicted(s.command(0)), 1e-14);
  EXPECT_GT((controller.estimate() - predicted(-2.0)).norm(), 1e-3);
}

TEST(CommandRateLimit, SetDesignKeepsThePreviousCommandAndResetClearsIt) {
  DynamicFollowerController controller(ControllerDesign::create(planarParameters(kInf, kInf)));
  const Eigen::Vector4d y(2.0, -1.0, 0.5, 0.3);
  const Eigen::VectorXd before = controller.step({y}).command;
  ASSERT_GT(before.norm(), 1.0);
  const ControllerDesign limited = ControllerDesign::create(planarParameters(20.0, kInf));
  testing::changeDesign(&controller, limited);
  EXPECT_EQ(controller.previousCommand(), before);
  const Eigen::Vector4d far(-6.0, 5.0, -2.0, 1.0);
  const DynamicFollowerStatus& next = controller.step({far});
  EXPECT_TRUE(next.command_rate_limited);
  EXPECT_LE(euclideanNorm(next.command - before), 20.0 * limited.period);
  EXPECT_NEAR(euclideanNorm(next.command - before), 20.0 * limited.period, 1e-12);

  // A smaller acceleration limit moves the kept command into its ball.
  const Eigen::VectorXd kept = controller.previousCommand();
  testing::changeDesign(&controller,
                        ControllerDesign::create(planarParameters(20.0, 0.5 * kept.norm())));
  EXPECT_MATRIX_NEAR(controller.previousCommand(), 0.5 * kept, 1e-15);

  controller.reset();
  EXPECT_EQ(controller.previousCommand(), Eigen::VectorXd::Zero(2));
  const DynamicFollowerStatus& restarted = controller.step({far});
  EXPECT_NEAR(euclideanNorm(restarted.command), 20.0 * limited.period, 1e-12);
}

TEST(CommandRateLimit, ScenarioKeyIsValidated) {
  const std::string path = testing::scenarioPath("paper_run2.yaml");
  EXPECT_TRUE(std::isinf(loadScenarioFile(path).controller.jerk_limit));  // absent: no limit
  EXPECT_DOUBLE_EQ(loadScenarioFile(path, {"controller.jerk_limit=12.5"}).controller.jerk_limit,
                   12.5);
  EXPECT_TRUE(
      std::isinf(loadScenarioFile(path, {"controller.jerk_limit=.inf"}).controller.jerk_limit));
  for (const std::string value : {"0", "-1", ".nan", "-.inf"}) {
    try {
      loadScenarioFile(path, {"controller.jerk_limit=" + value});
      ADD_FAILURE() << "accepted controller.jerk_limit=" << value;
    } catch (const ParameterError& error) {
      EXPECT_EQ(error.key(), "controller.jerk_limit") << value;
      EXPECT_NE(std::string(error.what()).find("controller.jerk_limit"), std::string::npos);
    }
  }
  ControllerParameters p = testing::paperParameters();
  p.jerk_limit = std::nan("");
  EXPECT_THROW(ControllerDesign::create(p), ParameterError);
}

}  // namespace
}  // namespace projection_collision_avoidance
