/// VelocityLagVehicle and UnicycleVehicle (sim/VehicleModels.hpp): the exact steps against their
/// closed forms and against RK4 with fine steps, τ = 0, the limits, the arc's straight-line limit,
/// refused commands (the last valid one kept) and parameters refused by name.

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <string>

#include <Eigen/Core>
#include <gtest/gtest.h>

#include "projection_collision_avoidance/core/ParameterError.hpp"
#include "projection_collision_avoidance/sim/VehicleModels.hpp"

#include "EigenTestHelpers.hpp"

namespace projection_collision_avoidance {
namespace {

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

/// The unicycle with a lag, v and ω towards (vc, ωc) with time constant τ, by RK4.
State5 unicycleReference(const State5& x0, double vc, double omegac, double tau, double h) {
  const std::function<State5(const State5&)> f = [=](const State5& s) {
    State5 d;
    d << s(3) * std::cos(s(2)), s(3) * std::sin(s(2)), s(4), (vc - s(3)) / tau,
        (omegac - s(4)) / tau;
    return d;
  };
  return rk4(f, x0, h, 20000);
}

/// a − b wrapped to [−π, π].
double angleBetween(double a, double b) { return std::remainder(a - b, 2.0 * kPi); }

template <typename Make>
std::string refusedKey(Make make) {
  try {
    make();
  } catch (const ParameterError& e) {
    return e.key();
  }
  return "";
}

// --- VelocityLagVehicle

TEST(VelocityLagVehicle, StepMatchesTheClosedForm) {
  VelocityLagParameters parameters;
  parameters.velocity_lag = 0.2;
  const Eigen::Vector3d p0(1.0, -2.0, 0.5);
  const Eigen::Vector3d v0(0.3, 0.1, -0.2);
  const Eigen::Vector3d vc(1.5, -0.7, 0.4);
  VelocityLagVehicle vehicle(3, p0, v0, parameters);
  ASSERT_TRUE(vehicle.setCommand(vc));
  const double h = 0.37;
  vehicle.advance(h);
  const double e = std::exp(-h / 0.2);
  EXPECT_MATRIX_NEAR(vehicle.velocity(), vc + (v0 - vc) * e, 1e-14);
  EXPECT_MATRIX_NEAR(vehicle.position(), p0 + vc * h + (v0 - vc) * 0.2 * (1.0 - e), 1e-14);
}

TEST(VelocityLagVehicle, StepMatchesRk4AndSplitStepsCompose) {
  VelocityLagParameters parameters;
  parameters.velocity_lag = 0.15;
  const Eigen::Vector3d p0(0.0, 1.0, 0.0);
  const Eigen::Vector3d v0(-1.0, 0.5, 0.0);
  const Eigen::Vector3d vc(2.0, 0.0, 0.0);
  using State6 = Eigen::Matrix<double, 6, 1>;
  const std::function<State6(const State6&)> f = [&](const State6& s) {
    State6 d;
    d << s.tail<3>(), (vc - s.tail<3>()) / 0.15;
    return d;
  };
  State6 x0;
  x0 << p0, v0;
  const State6 reference = rk4(f, x0, 0.8, 20000);
  VelocityLagVehicle one(2, p0, v0, parameters);
  VelocityLagVehicle many(2, p0, v0, parameters);
  one.setCommand(vc);
  many.setCommand(vc);
  one.advance(0.8);
  for (int i = 0; i < 80; ++i) {
    many.advance(0.01);
  }
  EXPECT_MATRIX_NEAR(one.position(), reference.head<3>(), 1e-12);
  EXPECT_MATRIX_NEAR(one.velocity(), reference.tail<3>(), 1e-12);
  EXPECT_MATRIX_NEAR(many.position(), one.position(), 1e-12);
  EXPECT_MATRIX_NEAR(many.velocity(), one.velocity(), 1e-12);
}

TEST(VelocityLagVehicle, ReachesSixtyThreePercentOfAStepAtTau) {
  VelocityLagParameters parameters;
  parameters.velocity_lag = 0.4;
  VelocityLagVehicle vehicle(1, Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(), parameters);
  vehicle.setCommand(Eigen::Vector3d(2.0, 0.0, 0.0));
  vehicle.advance(0.4);
  EXPECT_NEAR(vehicle.velocity().x(), 2.0 * (1.0 - std::exp(-1.0)), 1e-14);
  EXPECT_NEAR(vehicle.velocity().x() / 2.0, 0.632, 1e-3);
  // A tiny step against a long lag keeps its digits: with x = h / τ, v = v_cmd (x − x²/2 + ...),
  // p = v_cmd τ (x²/2 − x³/6 + ...), where the closed form as written would cancel.
  VelocityLagVehicle slow(1, Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(), parameters);
  slow.setCommand(Eigen::Vector3d(1.0, 0.0, 0.0));
  slow.advance(1e-6);
  const double x = 1e-6 / 0.4;
  const double v = x - x * x / 2.0 + x * x * x / 6.0;
  const double p = 0.4 * (x * x / 2.0 - x * x * x / 6.0 + x * x * x * x / 24.0);
  EXPECT_NEAR(slow.velocity().x(), v, 1e-15 * v);
  EXPECT_NEAR(slow.position().x(), p, 1e-15 * p);
}

TEST(VelocityLagVehicle, ZeroLagTakesTheCommandAtOnce) {
  VelocityLagVehicle vehicle(2, Eigen::Vector3d(1.0, 1.0, 0.0), Eigen::Vector3d(5.0, 5.0, 0.0),
                             VelocityLagParameters{});
  vehicle.setCommand(Eigen::Vector3d(-1.0, 2.0, 0.0));
  vehicle.advance(0.5);
  EXPECT_MATRIX_NEAR(vehicle.velocity(), Eigen::Vector3d(-1.0, 2.0, 0.0), 0.0);
  EXPECT_MATRIX_NEAR(vehicle.position(), Eigen::Vector3d(0.5, 2.0, 0.0), 1e-15);
  vehicle.advance(0.0);  // h = 0 changes nothing
  EXPECT_MATRIX_NEAR(vehicle.position(), Eigen::Vector3d(0.5, 2.0, 0.0), 1e-15);
  EXPECT_THROW(vehicle.advance(-0.1), std::invalid_argument);
  EXPECT_THROW(vehicle.advance(kNaN), std::invalid_argument);
  EXPECT_THROW(vehicle.advance(kInf), std::invalid_argument);
}

TEST(VelocityLagVehicle, SpeedLimitScalesTheCommandOntoItKeepingItsDirection) {
  VelocityLagParameters parameters;
  parameters.velocity_lag = 0.1;
  parameters.max_speed = 1.0;
  VelocityLagVehicle vehicle(2, Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(), parameters);
  ASSERT_TRUE(vehicle.setCommand(Eigen::Vector3d(3.0, 4.0, 0.0)));
  EXPECT_TRUE(vehicle.commandLimited());
  EXPECT_MATRIX_NEAR(vehicle.command(), Eigen::Vector3d(0.6, 0.8, 0.0), 1e-15);
  for (int i = 0; i < 200; ++i) {
    vehicle.advance(0.01);
    EXPECT_LE(vehicle.velocity().norm(), 1.0 + 1e-12);
  }
  EXPECT_MATRIX_NEAR(vehicle.velocity(), Eigen::Vector3d(0.6, 0.8, 0.0), 1e-8);
  // Huge finite entries do not overflow the scaling.
  ASSERT_TRUE(vehicle.setCommand(Eigen::Vector3d(1e300, -1e300, 0.0)));
  EXPECT_NEAR(vehicle.command().norm(), 1.0, 1e-12);
  ASSERT_TRUE(vehicle.setCommand(Eigen::Vector3d(0.3, 0.0, 0.0)));
  EXPECT_FALSE(vehicle.commandLimited());
}

TEST(VelocityLagVehicle, NonFiniteCommandsAreRefusedAndTheLastValidOneKept) {
  VelocityLagVehicle vehicle(3, Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(),
                             VelocityLagParameters{});
  ASSERT_TRUE(vehicle.setCommand(Eigen::Vector3d(1.0, 2.0, 3.0)));
  EXPECT_FALSE(vehicle.setCommand(Eigen::Vector3d(kNaN, 0.0, 0.0)));
  EXPECT_FALSE(vehicle.setCommand(Eigen::Vector3d(0.0, kInf, 0.0)));
  EXPECT_FALSE(vehicle.setCommand(Eigen::Vector3d(0.0, 0.0, -kInf)));
  EXPECT_MATRIX_NEAR(vehicle.command(), Eigen::Vector3d(1.0, 2.0, 3.0), 0.0);
  vehicle.advance(1.0);
  EXPECT_TRUE(vehicle.position().allFinite());
}

TEST(VelocityLagVehicle, EntriesBeyondTheAxesAreIgnored) {
  VelocityLagVehicle vehicle(1, Eigen::Vector3d(1.0, 7.0, 7.0), Eigen::Vector3d(0.0, 7.0, 7.0),
                             VelocityLagParameters{});
  EXPECT_MATRIX_NEAR(vehicle.position(), Eigen::Vector3d(1.0, 0.0, 0.0), 0.0);
  // A NaN beyond the axes is not part of the command.
  ASSERT_TRUE(vehicle.setCommand(Eigen::Vector3d(2.0, kNaN, 5.0)));
  vehicle.advance(1.0);
  EXPECT_MATRIX_NEAR(vehicle.position(), Eigen::Vector3d(3.0, 0.0, 0.0), 1e-15);
  EXPECT_MATRIX_NEAR(vehicle.velocity(), Eigen::Vector3d(2.0, 0.0, 0.0), 0.0);
}

TEST(VelocityLagVehicle, BodyVelocityIsTheWorldVelocityTurnedBackByTheHeading) {
  VelocityLagParameters parameters;
  parameters.heading = kPi / 2.0;  // body x along world y
  VelocityLagVehicle vehicle(3, Eigen::Vector3d::Zero(), Eigen::Vector3d(0.0, 2.0, 0.5),
                             parameters);
  EXPECT_MATRIX_NEAR(vehicle.bodyVelocity(), Eigen::Vector3d(2.0, 0.0, 0.5), 1e-15);
  parameters.heading = kPi / 6.0;
  VelocityLagVehicle turned(2, Eigen::Vector3d::Zero(), Eigen::Vector3d(1.0, 0.0, 0.0), parameters);
  EXPECT_MATRIX_NEAR(turned.bodyVelocity(), Eigen::Vector3d(std::sqrt(3.0) / 2.0, -0.5, 0.0),
                     1e-15);
}

TEST(VelocityLagVehicle, RefusesUnusableParametersByName) {
  const std::string key = "~vehicles/follower_1";
  const auto make = [&](double tau, double max_speed, double heading) {
    return refusedKey([&] {
      VelocityLagVehicle(2, Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(),
                         VelocityLagParameters{tau, max_speed, heading}, key);
    });
  };
  EXPECT_EQ(make(-0.1, kInf, 0.0), key + "/velocity_lag");
  EXPECT_EQ(make(kNaN, kInf, 0.0), key + "/velocity_lag");
  EXPECT_EQ(make(kInf, kInf, 0.0), key + "/velocity_lag");
  EXPECT_EQ(make(0.1, 0.0, 0.0), key + "/max_speed");
  EXPECT_EQ(make(0.1, -1.0, 0.0), key + "/max_speed");
  EXPECT_EQ(make(0.1, kNaN, 0.0), key + "/max_speed");
  EXPECT_EQ(make(0.1, 1.0, kNaN), key + "/heading");
  EXPECT_EQ(make(0.1, 1.0, kInf), key + "/heading");
  EXPECT_EQ(make(0.0, kInf, 1.0), "");
  EXPECT_THROW(VelocityLagVehicle(4, Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(), {}),
               std::invalid_argument);
  EXPECT_THROW(VelocityLagVehicle(2, Eigen::Vector3d(kNaN, 0.0, 0.0), Eigen::Vector3d::Zero(), {}),
               std::invalid_argument);
}

// --- The arc

TEST(UnicycleArc, MatchesTheClosedFormOfTheArc) {
  for (const double omega : {0.7, -2.3, 15.0}) {
    double x = 1.0;
    double y = -1.0;
    double theta = 0.4;
    const double v = 1.3;
    const double h = 0.25;
    advanceArc(v, omega, h, &x, &y, &theta);
    const double theta1 = 0.4 + omega * h;
    EXPECT_NEAR(theta, theta1, 1e-15);
    EXPECT_NEAR(x, 1.0 + v * (std::sin(theta1) - std::sin(0.4)) / omega, 1e-14) << omega;
    EXPECT_NEAR(y, -1.0 - v * (std::cos(theta1) - std::cos(0.4)) / omega, 1e-14) << omega;
  }
}

TEST(UnicycleArc, TendsToTheStraightLineAsTheYawRateVanishes) {
  const double v = 2.0;
  const double h = 0.1;
  const double theta0 = 1.1;
  double x = 0.0;
  double y = 0.0;
  double theta = theta0;
  advanceArc(v, 0.0, h, &x, &y, &theta);  // ω = 0 exactly: the straight line
  EXPECT_NEAR(x, v * h * std::cos(theta0), 1e-16);
  EXPECT_NEAR(y, v * h * std::sin(theta0), 1e-16);
  EXPECT_EQ(theta, theta0);
  for (const double omega : {1e-14, 1e-9, 1e-5, -1e-3}) {
    double xo = 0.0;
    double yo = 0.0;
    double to = theta0;
    advanceArc(v, omega, h, &xo, &yo, &to);
    // The arc's deviation from the chord at the middle: v h (ω h) / 2 to first order.
    const double bound = 0.5 * v * h * std::abs(omega * h) + 1e-16;
    EXPECT_NEAR(xo, x, bound) << omega;
    EXPECT_NEAR(yo, y, bound) << omega;
    EXPECT_TRUE(std::isfinite(xo) && std::isfinite(yo));
  }
}

// --- UnicycleVehicle

TEST(UnicycleVehicle, ConstantCommandsDriveACircleOfRadiusVOverOmega) {
  UnicycleState start;
  start.x = 2.0;
  start.y = 1.0;
  start.theta = 0.3;
  UnicycleVehicle vehicle(start, UnicycleParameters{});
  const double v = 0.8;
  const double omega = 0.4;
  ASSERT_TRUE(vehicle.setCommand(v, omega));
  const double r = v / omega;
  const double cx = start.x - r * std::sin(start.theta);
  const double cy = start.y + r * std::cos(start.theta);
  for (int k = 1; k <= 2000; ++k) {  // 20 s, more than one lap
    vehicle.advance(0.01);
    const UnicycleState& s = vehicle.state();
    const double theta = start.theta + omega * 0.01 * k;
    ASSERT_NEAR(s.x, cx + r * std::sin(theta), 1e-11) << k;
    ASSERT_NEAR(s.y, cy - r * std::cos(theta), 1e-11) << k;
    ASSERT_NEAR(angleBetween(s.theta, theta), 0.0, 1e-12) << k;
    ASSERT_LE(std::abs(s.theta), kPi) << "heading wrapped to [-pi, pi]";
  }
  EXPECT_NEAR(vehicle.worldVelocity().norm(), v, 1e-15);
}

TEST(UnicycleVehicle, LagMatchesRk4WithFineStepsWithinTheDocumentedError) {
  struct Case {
    double h;
    double tau;
  };
  const double v0 = 0.2;
  const double omega0 = -0.3;
  const double vc = 1.5;
  const double omegac = 0.8;
  for (const Case c : {Case{0.01, 0.2}, Case{0.1, 0.05}, Case{1.0, 0.3}, Case{5.0, 0.01}}) {
    UnicycleState start;
    start.theta = -0.5;
    start.v = v0;
    start.omega = omega0;
    UnicycleParameters parameters;
    parameters.velocity_lag = c.tau;
    UnicycleVehicle vehicle(start, parameters);
    vehicle.setCommand(vc, omegac);
    vehicle.advance(c.h);
    State5 x0;
    x0 << start.x, start.y, start.theta, start.v, start.omega;
    const State5 reference = unicycleReference(x0, vc, omegac, c.tau, c.h);
    // h h_s² |v' ω − v ω'| / 12, with |v' ω − v ω'| at most its bound over the step.
    const double hs = c.h / UnicycleVehicle::substeps(c.h, c.tau);
    const double rate_bound = (std::abs(vc - v0) * std::max(std::abs(omega0), std::abs(omegac)) +
                               std::max(std::abs(v0), std::abs(vc)) * std::abs(omegac - omega0)) /
                              c.tau;
    const double tolerance = c.h * hs * hs * rate_bound / 12.0 + 1e-12;
    const UnicycleState& s = vehicle.state();
    const double error = std::hypot(s.x - reference(0), s.y - reference(1));
    EXPECT_LE(error, tolerance) << c.h << " " << c.tau;
    EXPECT_GT(error, 0.0) << "with a lag the arcs are approximate";
    // θ, v and ω are exact.
    EXPECT_NEAR(angleBetween(s.theta, reference(2)), 0.0, 1e-11) << c.h << " " << c.tau;
    EXPECT_NEAR(s.v, reference(3), 1e-12);
    EXPECT_NEAR(s.omega, reference(4), 1e-12);
  }
}

TEST(UnicycleVehicle, LagVelocitiesAndHeadingFollowTheirClosedForms) {
  UnicycleState start;
  start.v = -0.5;
  start.omega = 1.0;
  UnicycleParameters parameters;
  parameters.velocity_lag = 0.25;
  UnicycleVehicle vehicle(start, parameters);
  vehicle.setCommand(1.0, -0.5);
  vehicle.advance(0.25);
  const double e = std::exp(-1.0);
  EXPECT_NEAR(vehicle.state().v, 1.0 + (-0.5 - 1.0) * e, 1e-14);
  EXPECT_NEAR(vehicle.state().omega, -0.5 + (1.0 + 0.5) * e, 1e-14);
  EXPECT_NEAR(vehicle.state().theta, -0.5 * 0.25 + 1.5 * 0.25 * (1.0 - e), 1e-14);
  // 63 % of a step of v at t = τ, from rest.
  UnicycleVehicle still(UnicycleState{}, parameters);
  still.setCommand(2.0, 0.0);
  still.advance(0.25);
  EXPECT_NEAR(still.state().v / 2.0, 1.0 - e, 1e-14);
}

TEST(UnicycleVehicle, SubstepsAreDocumentedCounts) {
  EXPECT_EQ(UnicycleVehicle::substeps(0.01, 0.0), 1);
  EXPECT_EQ(UnicycleVehicle::substeps(0.01, 0.2), UnicycleVehicle::kMinSubsteps);
  EXPECT_EQ(UnicycleVehicle::substeps(1.0, 0.1), 160);
  EXPECT_EQ(UnicycleVehicle::substeps(1.0, 1e-300), UnicycleVehicle::kMaxSubsteps);
}

TEST(UnicycleVehicle, ZeroLagTakesTheCommandAtOnce) {
  UnicycleVehicle vehicle(UnicycleState{}, UnicycleParameters{});
  vehicle.setCommand(1.0, 0.0);
  vehicle.advance(0.5);
  EXPECT_EQ(vehicle.state().v, 1.0);
  EXPECT_NEAR(vehicle.state().x, 0.5, 1e-15);
  EXPECT_EQ(vehicle.state().y, 0.0);
  EXPECT_THROW(vehicle.advance(-1.0), std::invalid_argument);
  EXPECT_THROW(vehicle.advance(kNaN), std::invalid_argument);
}

TEST(UnicycleVehicle, LimitsClampEachPartOnItsOwn) {
  UnicycleParameters parameters;
  parameters.max_speed = 0.5;
  parameters.max_yaw_rate = 1.0;
  UnicycleVehicle vehicle(UnicycleState{}, parameters);
  ASSERT_TRUE(vehicle.setCommand(2.0, 0.5));
  EXPECT_EQ(vehicle.commandSpeed(), 0.5);
  EXPECT_EQ(vehicle.commandYawRate(), 0.5);
  EXPECT_TRUE(vehicle.speedLimited());
  EXPECT_FALSE(vehicle.yawRateLimited());
  ASSERT_TRUE(vehicle.setCommand(-0.1, -3.0));
  EXPECT_EQ(vehicle.commandSpeed(), -0.1);
  EXPECT_EQ(vehicle.commandYawRate(), -1.0);
  EXPECT_FALSE(vehicle.speedLimited());
  EXPECT_TRUE(vehicle.yawRateLimited());
  ASSERT_TRUE(vehicle.setCommand(1e308, -1e308));
  vehicle.advance(0.1);
  EXPECT_EQ(vehicle.state().v, 0.5);
  EXPECT_EQ(vehicle.state().omega, -1.0);
}

TEST(UnicycleVehicle, NonFiniteCommandsAreRefusedAndTheLastValidOneKept) {
  UnicycleVehicle vehicle(UnicycleState{}, UnicycleParameters{});
  ASSERT_TRUE(vehicle.setCommand(0.3, 0.2));
  EXPECT_FALSE(vehicle.setCommand(kNaN, 0.0));
  EXPECT_FALSE(vehicle.setCommand(0.0, kInf));
  EXPECT_FALSE(vehicle.setCommand(-kInf, kNaN));
  EXPECT_EQ(vehicle.commandSpeed(), 0.3);
  EXPECT_EQ(vehicle.commandYawRate(), 0.2);
  vehicle.advance(1.0);
  EXPECT_EQ(vehicle.state().v, 0.3);
}

TEST(UnicycleVehicle, RefusesUnusableParametersByName) {
  const std::string key = "~vehicles/follower_2";
  const auto make = [&](double tau, double max_speed, double max_yaw_rate) {
    return refusedKey([&] {
      UnicycleVehicle(UnicycleState{}, UnicycleParameters{tau, max_speed, max_yaw_rate}, key);
    });
  };
  EXPECT_EQ(make(-1.0, kInf, kInf), key + "/velocity_lag");
  EXPECT_EQ(make(kNaN, kInf, kInf), key + "/velocity_lag");
  EXPECT_EQ(make(0.0, 0.0, kInf), key + "/max_speed");
  EXPECT_EQ(make(0.0, kNaN, kInf), key + "/max_speed");
  EXPECT_EQ(make(0.0, 1.0, -2.0), key + "/max_yaw_rate");
  EXPECT_EQ(make(0.0, 1.0, kNaN), key + "/max_yaw_rate");
  EXPECT_EQ(make(0.0, 1.0, 1.0), "");
  UnicycleState bad;
  bad.theta = kInf;
  EXPECT_THROW(UnicycleVehicle(bad, UnicycleParameters{}), std::invalid_argument);
}

}  // namespace
}  // namespace projection_collision_avoidance
