/// UnicycleVehicle (sim/VehicleModels.hpp): the circle of constant commands, the lagged step
/// against RK4 with fine steps within its documented error, the exact v, ω and θ, the substep
/// counts, τ = 0, the limits, refused commands (the last valid one kept) and parameters refused
/// by name.

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

using testing::angleBetween;
using testing::kInf;
using testing::kNaN;
using testing::kPi;
using testing::refusedKey;
using testing::State5;
using testing::unicycleReference;

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
