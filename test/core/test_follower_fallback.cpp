/// The fallback of a follower that has lost its measurement (FollowerController::step() without a
/// measurement), its parameters, and the choice of mode from the ages of the inputs
/// (selectFollowerMode()).

#include <cmath>
#include <limits>

#include <gtest/gtest.h>

#include "projection_collision_avoidance/core/ControllerDesign.hpp"
#include "projection_collision_avoidance/core/DynamicFollowerController.hpp"
#include "projection_collision_avoidance/core/FollowerController.hpp"
#include "projection_collision_avoidance/core/FollowerMode.hpp"
#include "projection_collision_avoidance/core/ParameterError.hpp"
#include "projection_collision_avoidance/scenario/ScenarioLoader.hpp"

#include "EigenTestHelpers.hpp"
#include "TestScenarios.hpp"

namespace projection_collision_avoidance {
namespace {

using Controller1D = FollowerController<DoubleIntegrator1D>;

/// Exact zero-order-hold step of the relative error of two 1-D double integrators,
/// xi' = A xi + B (u_1 - u_2), over T.
Eigen::Vector2d relativeStep(const Eigen::Vector2d& xi, double relative_input, double period) {
  return {xi(0) + xi(1) * period + 0.5 * relative_input * period * period,
          xi(1) + relative_input * period};
}

TEST(FollowerFallback, DefaultGainBrakesTheRelativeVelocity) {
  const ControllerDesign design = ControllerDesign::create(testing::paperParameters());
  EXPECT_MATRIX_NEAR(design.fallback_gain, Eigen::RowVector2d(0.0, 1.0), 0.0);
  Controller1D controller(design);
  // The leader pulls away at 0.8 m/s, 1 m beyond the slot, when the measurement stops.
  Eigen::Vector2d xi(1.0, 0.8);
  controller.resetEstimate(xi);
  for (int k = 0; k < 1000; ++k) {  // 10 s at 100 Hz
    const auto& status = controller.step({});
    ASSERT_TRUE(status.fallback);
    ASSERT_EQ(status.baseline_command(0), 0.0);
    ASSERT_EQ(status.tracker_command(0), 0.0);
    // u_2 = K_f xi_hat = k_v v_hat: the follower accelerates after the leader.
    ASSERT_DOUBLE_EQ(status.command(0), status.estimate(1));
    xi = relativeStep(xi, -status.command(0), design.period);
    // The model is exact here (u_1 = 0, no disturbance), so the prediction follows xi.
    ASSERT_MATRIX_NEAR(controller.estimate(), xi, 1e-9) << "step " << k;
  }
  // About e^{-10} of the initial 0.8 m/s is left (0.99^1000 with the sampled brake); the gap
  // grew by v_0 / k_v = 0.8 m, less the sampling's T/2 share.
  EXPECT_LT(std::abs(xi(1)), 0.8 * std::exp(-10.0));
  EXPECT_NEAR(xi(0), 1.0 + 0.8 * (1.0 - std::exp(-10.0)), 0.01);
}

TEST(FollowerFallback, EstimateStaysInsideTheBound) {
  ControllerParameters p = testing::paperParameters();
  p.fallback_gain = Eigen::RowVector2d::Zero();  // coast: the predicted xi runs off
  const ControllerDesign design = ControllerDesign::create(p);
  Controller1D controller(design);
  controller.resetEstimate(Eigen::Vector2d(3.5, 1.5));  // 3.81 m, moving outward
  bool projected = false;
  for (int k = 0; k < 500; ++k) {
    const auto& status = controller.step({});
    ASSERT_LE(controller.estimate().norm(), design.xi_max) << "step " << k;
    ASSERT_EQ(status.command(0), 0.0);
    projected = projected || status.projection_active;
  }
  EXPECT_TRUE(projected);
  EXPECT_GT(controller.estimate().norm(), design.xi_soft);
}

TEST(FollowerFallback, CommandIsSaturated) {
  ControllerParameters p = testing::paperParameters();
  p.acceleration_limit = 0.25;
  const ControllerDesign design = ControllerDesign::create(p);
  Controller1D controller(design);
  controller.resetEstimate(Eigen::Vector2d(0.0, -2.0));  // closing at 2 m/s
  Eigen::Vector2d xi(0.0, -2.0);
  const auto& first = controller.step({});
  EXPECT_TRUE(first.command_saturated);
  EXPECT_DOUBLE_EQ(first.command(0), -0.25);
  EXPECT_DOUBLE_EQ(first.fallback_command(0), -2.0);
  xi = relativeStep(xi, 0.25, design.period);
  // The prediction is integrated with the saturated command, the one that acts.
  EXPECT_MATRIX_NEAR(controller.estimate(), xi, 1e-12);
}

TEST(FollowerFallback, SharedLeaderInputIsMatched) {
  ControllerParameters p = testing::paperParameters();
  p.leader_input_in_command = true;
  p.leader_input_in_estimator = true;
  const ControllerDesign design = ControllerDesign::create(p);
  Controller1D controller(design);
  Eigen::Vector2d xi(0.5, 0.0);
  controller.resetEstimate(xi);
  const Eigen::Matrix<double, 1, 1> leader_input(-1.5);  // the leader brakes
  for (int k = 0; k < 300; ++k) {
    const auto& status = controller.step({std::nullopt, leader_input});
    ASSERT_DOUBLE_EQ(status.feedforward_command(0), -1.5);
    ASSERT_NEAR(status.command(0), -1.5, 1e-9);  // the relative velocity stays zero
    xi = relativeStep(xi, leader_input(0) - status.command(0), design.period);
  }
  EXPECT_MATRIX_NEAR(xi, Eigen::Vector2d(0.5, 0.0), 1e-9);
  EXPECT_MATRIX_NEAR(controller.estimate(), xi, 1e-9);
}

TEST(FollowerFallback, UnsharedLeaderInputIsNotPredicted) {
  // Without sharing into the estimator the prediction assumes u_1 = u_ff, as step() does.
  ControllerParameters p = testing::paperParameters();
  p.leader_input_in_command = true;
  Controller1D controller(ControllerDesign::create(p));
  controller.resetEstimate(Eigen::Vector2d(0.5, 0.0));
  const auto& status = controller.step({std::nullopt, Eigen::Matrix<double, 1, 1>(2.0)});
  EXPECT_DOUBLE_EQ(status.command(0), 2.0);
  EXPECT_MATRIX_NEAR(controller.estimate(), Eigen::Vector2d(0.5, 0.0), 1e-12);
}

TEST(FollowerFallback, NextMeasurementResumesTheLaws) {
  const ControllerDesign design = ControllerDesign::create(testing::paperParameters());
  Controller1D controller(design);
  const Eigen::Vector2d y(1.0, 0.2);
  controller.step({y});
  for (int k = 0; k < 50; ++k) {
    controller.step({});
  }
  const Eigen::Vector2d predicted = controller.estimate();
  const auto& status = controller.step({y});
  EXPECT_FALSE(status.fallback);
  EXPECT_EQ(status.fallback_command(0), 0.0);
  EXPECT_MATRIX_NEAR(status.estimate, predicted, 0.0);  // the estimate carries over
  EXPECT_DOUBLE_EQ(status.baseline_command(0), 1.0 * 1.0 + 1.4 * 0.2);
}

TEST(FollowerFallback, RuntimeControllerDispatches) {
  const ControllerDesign design = ControllerDesign::create(testing::paperParameters());
  DynamicFollowerController runtime(design);
  Controller1D fixed(design);
  const Eigen::Vector2d y(2.0, -0.5);
  runtime.step({y});
  fixed.step({y});
  for (int k = 0; k < 100; ++k) {
    const auto& a = runtime.step({});
    const auto& b = fixed.step({});
    ASSERT_TRUE(a.fallback);
    ASSERT_MATRIX_NEAR(a.command, b.command, 0.0);
    ASSERT_MATRIX_NEAR(a.fallback_command, b.fallback_command, 0.0);
    ASSERT_MATRIX_NEAR(a.estimate, b.estimate, 0.0);
  }
  const Eigen::Matrix<double, 1, 1> u1(0.5);
  EXPECT_MATRIX_NEAR(runtime.step({std::nullopt, u1}).command,
                     fixed.step({std::nullopt, u1}).command, 0.0);
}

void expectRefused(const ControllerParameters& p, const std::string& key) {
  try {
    ControllerDesign::create(p);
    ADD_FAILURE() << "accepted; expected a refusal naming " << key;
  } catch (const ParameterError& error) {
    EXPECT_EQ(error.key(), key) << error.what();
  }
}

TEST(FollowerFallback, GainIsValidated) {
  ControllerParameters p = testing::paperParameters();
  p.fallback_gain = Eigen::Matrix2d::Identity();  // 2 x 2, must be 1 x 2
  expectRefused(p, "controller.fallback.gain");
  p.fallback_gain = Eigen::RowVector2d(0.0, std::numeric_limits<double>::quiet_NaN());
  expectRefused(p, "controller.fallback.gain");
  p.fallback_gain = Eigen::RowVector2d(0.0, -1.0);  // accelerates away: eigenvalue +1
  expectRefused(p, "controller.fallback.gain");
  p.fallback_gain = Eigen::RowVector2d(1.0, 2.0);  // brakes and holds position
  EXPECT_NO_THROW(ControllerDesign::create(p));
  EXPECT_THROW(doubleIntegratorFallbackGain(1, 0.0), ParameterError);
  EXPECT_THROW(doubleIntegratorFallbackGain(1, std::numeric_limits<double>::infinity()),
               ParameterError);
  EXPECT_MATRIX_NEAR(doubleIntegratorFallbackGain(2, 3.0),
                     (Eigen::Matrix<double, 2, 4>() << 0, 0, 3, 0, 0, 0, 0, 3).finished(), 0.0);
}

TEST(FollowerFallback, ScenarioKeys) {
  const std::string path = testing::scenarioPath("paper_run2.yaml");
  EXPECT_EQ(loadScenarioFile(path).controller.fallback_gain.size(), 0);  // absent: default
  EXPECT_MATRIX_NEAR(
      loadScenarioFile(path, {"controller.fallback.velocity_gain=2.5"}).controller.fallback_gain,
      Eigen::RowVector2d(0.0, 2.5), 0.0);
  EXPECT_MATRIX_NEAR(
      loadScenarioFile(path, {"controller.fallback.gain=[[0.5, 2]]"}).controller.fallback_gain,
      Eigen::RowVector2d(0.5, 2.0), 0.0);
  const auto keyOfRefusal = [&path](const std::vector<std::string>& overrides) -> std::string {
    try {
      ControllerDesign::create(loadScenarioFile(path, overrides).controller);
    } catch (const ParameterError& error) {
      return error.key();
    }
    return "accepted";
  };
  EXPECT_EQ(keyOfRefusal({"controller.fallback.velocity_gain=-1"}),
            "controller.fallback.velocity_gain");
  EXPECT_EQ(keyOfRefusal({"controller.fallback.gain=[[0, 1, 2]]"}), "controller.fallback.gain");
  EXPECT_EQ(
      keyOfRefusal({"controller.fallback.gain=[[0, 1]]", "controller.fallback.velocity_gain=1"}),
      "controller.fallback.gain");
  EXPECT_EQ(keyOfRefusal({"controller.fallback.brake=1"}), "controller.fallback.brake");
}

TEST(FollowerMode, FollowsTheAgesOfTheInputs) {
  const FollowerTimeouts timeouts{0.5, 0.3};
  FollowerInputAges ages;
  EXPECT_EQ(selectFollowerMode(ages, timeouts), FollowerMode::kWaiting);
  ages.have_measurement = true;
  ages.measurement_age = 0.5;
  EXPECT_EQ(selectFollowerMode(ages, timeouts), FollowerMode::kTracking);
  ages.measurement_age = 0.51;
  EXPECT_EQ(selectFollowerMode(ages, timeouts), FollowerMode::kMeasurementLost);
  ages.measurement_age = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(selectFollowerMode(ages, timeouts), FollowerMode::kMeasurementLost);
  ages.measurement_age = 0.01;
  ages.leader_age = 10.0;  // never heard: not lost
  EXPECT_EQ(selectFollowerMode(ages, timeouts), FollowerMode::kTracking);
  ages.have_leader = true;
  EXPECT_EQ(selectFollowerMode(ages, timeouts), FollowerMode::kLeaderLost);
  ages.leader_age = 0.3;
  EXPECT_EQ(selectFollowerMode(ages, timeouts), FollowerMode::kTracking);
  ages.measurement_age = 2.0;  // both stale: the measurement decides
  ages.leader_age = 2.0;
  EXPECT_EQ(selectFollowerMode(ages, timeouts), FollowerMode::kMeasurementLost);
  EXPECT_STREQ(toString(FollowerMode::kMeasurementLost), "measurement_lost");
  EXPECT_STREQ(toString(FollowerMode::kLeaderLost), "leader_lost");
  EXPECT_STREQ(toString(FollowerMode::kTracking), "tracking");
  EXPECT_STREQ(toString(FollowerMode::kWaiting), "waiting");
}

}  // namespace
}  // namespace projection_collision_avoidance
