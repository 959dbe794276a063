/// VelocityLagVehicle (sim/VehicleModels.hpp) and the unicycle's arc: the exact steps against
/// their closed forms and against RK4 with fine steps, τ = 0, the 63 % of a step at τ, the speed
/// limit, refused commands (the last valid one kept), parameters refused by name, the arc's
/// straight-line limit. The UnicycleVehicle: test_unicycle_vehicle.cpp.

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
#include "VehicleTestHelpers.hpp"

namespace projection_collision_avoidance {
namespace {

using testing::kInf;
using testing::kNaN;
using testing::kPi;
using testing::refusedKey;
using testing::rk4;

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

}  // namespace
}  // namespace projection_collision_avoidance
