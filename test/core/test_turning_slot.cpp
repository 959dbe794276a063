/// Turning slots (doc/math.md, "Turning slots"): the slot heading (T1), the turned slot (T2), its
/// acceleration (T3) and the closed loop with them (no roscore).

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <random>
#include <string>

#include <gtest/gtest.h>

#include "projection_collision_avoidance/core/FollowerController.hpp"
#include "projection_collision_avoidance/core/Formation.hpp"
#include "projection_collision_avoidance/core/ParameterError.hpp"
#include "projection_collision_avoidance/core/TurningSlot.hpp"
#include "projection_collision_avoidance/scenario/ScenarioLoader.hpp"
#include "projection_collision_avoidance/sim/SampledSimulator.hpp"

#include "TestScenarios.hpp"

namespace projection_collision_avoidance {
namespace {

constexpr double kPi = 3.141592653589793;
constexpr double kPeriod = 0.01;

using State3 = Eigen::Matrix<double, 6, 1>;
using Input3 = Eigen::Matrix<double, 3, 1>;

/// theta(t) = 0.3 + 0.7 sin(1.3 t) and its two derivatives.
SlotHeadingSample smoothHeading(double t) {
  return {0.3 + 0.7 * std::sin(1.3 * t), 0.91 * std::cos(1.3 * t), -1.183 * std::sin(1.3 * t)};
}

/// (T2) and (T3) against finite differences of R(theta(t)) d_p: D's velocity part is the
/// derivative of its position part, and u_r is minus its second derivative; z is not turned.
TEST(TurningSlotGeometry, OffsetAndAccelerationAreTheSlotsDerivatives) {
  State3 d;
  d << 5.0, -2.0, 1.5, 0.0, 0.0, 0.0;
  const double h = 1e-4;
  for (const double t : {0.0, 0.4, 1.7, 3.2}) {
    State3 before;
    State3 now;
    State3 after;
    turningSlotOffset(d, 3, smoothHeading(t - h), &before);
    turningSlotOffset(d, 3, smoothHeading(t), &now);
    turningSlotOffset(d, 3, smoothHeading(t + h), &after);
    const Eigen::Vector3d velocity = (after.head<3>() - before.head<3>()) / (2.0 * h);
    const Eigen::Vector3d second =
        (after.head<3>() - 2.0 * now.head<3>() + before.head<3>()) / (h * h);
    EXPECT_LT((now.tail<3>() - velocity).norm(), 1e-6) << t;
    Input3 slot_acceleration;
    turningSlotAcceleration(d, 3, smoothHeading(t), &slot_acceleration);
    EXPECT_LT((slot_acceleration + second).norm(), 1e-5) << t;
    EXPECT_DOUBLE_EQ(now(2), d(2));
    EXPECT_NEAR(now.head<3>().norm(), d.head<3>().norm(), 1e-12);  // a rotation
  }
  State3 unturned;
  turningSlotOffset(d, 3, SlotHeadingSample{}, &unturned);
  EXPECT_EQ(unturned, d);
}

/// (T1): whatever the headings (jumps, reversals, NaN, none), |theta'| <= max_yaw_rate,
/// |theta''| <= max_yaw_acceleration, theta' continuous (changes by at most beta T per tick).
TEST(SlotHeading, BoundsHoldForAnyHeadings) {
  SlotHeadingParameters parameters;
  parameters.max_yaw_rate = 0.7;
  parameters.max_yaw_acceleration = 1.3;
  parameters.natural_frequency = 4.0;
  for (const bool reversing : {false, true}) {
    parameters.reversing = reversing;
    SlotHeading heading(parameters, kPeriod);
    heading.reset(0.2);
    std::mt19937 random(7);
    std::uniform_real_distribution<double> angle(-10.0, 10.0);
    std::uniform_int_distribution<int> kind(0, 9);
    double previous_rate = 0.0;
    for (int k = 0; k < 20000; ++k) {
      std::optional<double> psi = angle(random);
      const int which = kind(random);
      if (which == 0) {
        psi.reset();
      } else if (which == 1) {
        psi = std::nan("");
      } else if (which == 2) {
        psi = std::numeric_limits<double>::infinity();
      }
      const SlotHeadingSample sample = heading.tick(psi);
      ASSERT_LE(std::abs(sample.rate), parameters.max_yaw_rate + 1e-12) << k;
      ASSERT_LE(std::abs(sample.acceleration), parameters.max_yaw_acceleration + 1e-12) << k;
      ASSERT_LE(std::abs(sample.rate - previous_rate),
                parameters.max_yaw_acceleration * kPeriod + 1e-12)
          << k;
      ASSERT_TRUE(std::isfinite(sample.angle));
      previous_rate = sample.rate;
    }
  }
}

/// A constant turn rate below the bound is followed without a steady lag (psi' fed forward).
TEST(SlotHeading, FollowsAConstantTurnWithoutLag) {
  SlotHeading heading(SlotHeadingParameters{}, kPeriod);
  heading.reset(1.0);
  const double rate = 0.3;  // rad/s, under max_yaw_rate 0.5
  SlotHeadingSample sample;
  for (int k = 0; k <= 3000; ++k) {
    sample = heading.tick(wrapAngle(1.0 + rate * k * kPeriod));
  }
  EXPECT_NEAR(wrapAngle(sample.angle - (1.0 + rate * 30.0)), 0.0, 1e-3);
  EXPECT_NEAR(sample.rate, rate, 1e-3);
}

/// A turn faster than max_yaw_rate is followed at max_yaw_rate.
TEST(SlotHeading, AFasterTurnIsFollowedAtTheRateBound) {
  SlotHeading heading(SlotHeadingParameters{}, kPeriod);
  heading.reset(0.0);
  SlotHeadingSample sample;
  for (int k = 0; k <= 1000; ++k) {
    sample = heading.tick(wrapAngle(2.0 * k * kPeriod));
  }
  EXPECT_NEAR(sample.rate, SlotHeadingParameters{}.max_yaw_rate, 1e-9);
}

/// Without a heading (a target at rest) the slot stops turning and holds.
TEST(SlotHeading, StopsTurningWithoutAHeading) {
  SlotHeading heading(SlotHeadingParameters{}, kPeriod);
  heading.reset(0.0);
  for (int k = 0; k < 200; ++k) {
    heading.tick(0.4 * k * kPeriod);
  }
  ASSERT_GT(heading.rate(), 0.1);
  SlotHeadingSample sample;
  for (int k = 0; k < 2000; ++k) {
    sample = heading.tick(std::nullopt);
  }
  EXPECT_LT(std::abs(sample.rate), 1e-6);
  const double held = sample.angle;
  for (int k = 0; k < 100; ++k) {
    sample = heading.tick(std::nullopt);
  }
  EXPECT_NEAR(sample.angle, held, 1e-6);
}

/// A target that drives backward (its velocity's direction flipped by pi): the slot swings round
/// it, or stays behind its body with reversing.
TEST(SlotHeading, AReversingTargetSwingsTheSlotUnlessReversing) {
  for (const bool reversing : {false, true}) {
    SlotHeadingParameters parameters;
    parameters.reversing = reversing;
    SlotHeading heading(parameters, kPeriod);
    heading.reset(0.0);
    SlotHeadingSample sample;
    for (int k = 0; k < 3000; ++k) {
      sample = heading.tick(kPi);
    }
    EXPECT_NEAR(std::abs(wrapAngle(sample.angle)), reversing ? 0.0 : kPi, 1e-3) << reversing;
  }
}

TEST(SlotHeading, HeadingOfAVelocity) {
  EXPECT_NEAR(*velocityHeading(0.0, 2.0, 0.5), kPi / 2, 1e-15);
  EXPECT_FALSE(velocityHeading(0.3, 0.3, 0.5).has_value());
  EXPECT_FALSE(velocityHeading(0.0, 0.0, 0.0).has_value());
  EXPECT_FALSE(velocityHeading(std::nan(""), 1.0, 0.5).has_value());
  EXPECT_NEAR(wrapAngle(3 * kPi), kPi, 1e-12);
  EXPECT_NEAR(wrapAngle(-kPi), kPi, 1e-12);
}

std::string keyOfScenarioError(const std::vector<std::string>& overrides,
                               const std::string& file = "figure_eight_2d.yaml") {
  try {
    loadScenarioFile(testing::scenarioPath(file), overrides).validate();
  } catch (const ParameterError& error) {
    return error.key();
  }
  return "";
}

TEST(TurningSlotScenario, RefusesWhatCannotTurn) {
  EXPECT_EQ(
      keyOfScenarioError({"formation.followers=1", "formation.slots=turning"}, "paper_run2.yaml"),
      "formation.slots");  // one axis: no plane to turn in
  EXPECT_EQ(keyOfScenarioError({"formation.followers=1", "formation.slots=sideways"}),
            "formation.slots");
  for (const std::string key :
       {"natural_frequency", "damping", "max_yaw_rate", "max_yaw_acceleration", "min_speed"}) {
    EXPECT_EQ(keyOfScenarioError({"formation.followers=1", "formation.slots=turning",
                                  "formation.turning." + key + "=-1"}),
              "formation.turning." + key);
  }
  EXPECT_EQ(keyOfScenarioError({"formation.followers=1", "formation.turning.yaw=1"}),
            "formation.turning.yaw");
  EXPECT_EQ(keyOfScenarioError({"formation.followers=1", "formation.slots=turning"}), "");
}

/// A scenario of the leader driving a circle of radius 10 m at 2 m/s with no push.
Scenario undisturbedCircle(const std::string& slots) {
  Scenario scenario = loadScenarioFile(testing::scenarioPath("turning_circle.yaml"),
                                       {"formation.followers=1", "formation.slots=" + slots});
  scenario.disturbance = SignalProfile{};
  scenario.duration = 40.0;
  return scenario;
}

/// Each follower starts on its slot turned by its target's initial heading.
TEST(TurningSlotScenario, FollowersStartOnTheirTurnedSlots) {
  Scenario scenario = undisturbedCircle("turning");
  scenario.leader_initial_state << 0.0, 0.0, 0.0, 2.0;  // heading +y
  const auto members =
      layoutFormation(scenario.formation, scenario.controller.separation,
                      scenario.leader_initial_state, scenario.follower_initial_state);
  EXPECT_NEAR(members[0].initial_heading, kPi / 2, 1e-15);
  EXPECT_NEAR(members[0].initial_state(0), 0.0, 1e-12);  // 5 m behind, along -y
  EXPECT_NEAR(members[0].initial_state(1), -5.0, 1e-12);
}

/// Largest ||xi|| after 20 s behind the undisturbed circling leader, with @p slots.
double lateError(const std::string& slots, double* slot_misalignment = nullptr) {
  double late_error = 0.0;
  double misalignment = 0.0;
  simulate(undisturbedCircle(slots), [&](const SimulationSample& sample) {
    if (sample.time > 20.0) {
      late_error = std::max(late_error, sample.relative_error.norm());
      const Eigen::Vector2d direction = sample.slot.head<2>().normalized();
      const Eigen::Vector2d velocity = sample.leader_state.tail<2>().normalized();
      misalignment = std::max(misalignment, (direction - velocity).norm());
    }
  });
  if (slot_misalignment != nullptr) {
    *slot_misalignment = misalignment;
  }
  return late_error;
}

/// With u_r the turning slot leaves xi the paper's dynamics: behind a circling leader the error
/// that is left is the one its unknown acceleration makes with a world slot (within the
/// sampling's share), and the slot points along the leader's velocity.
TEST(TurningSlotClosedLoop, TheSlotAccelerationLeavesThePapersErrorDynamics) {
  double misalignment = 1.0;
  const double turning = lateError("turning", &misalignment);
  const double world = lateError("world");
  EXPECT_GT(world, 0.01);  // the leader's 0.4 m/s^2, unknown to the follower
  EXPECT_NEAR(turning, world, 0.1 * world);
  EXPECT_LT(misalignment, 0.01);
  const SimulationSummary summary = simulate(undisturbedCircle("turning"));
  EXPECT_LE(summary.max_xi_hat, summary.xi_max + 1e-9);
}

/// (T3) as a known input: the command is the world slot's plus u_r, in tracking and in the
/// fallback, and the estimate the next step uses is the same (u_r is left out of the
/// augmentation the estimator integrates, and out of its drift in the fallback).
TEST(TurningSlotController, TheSlotAccelerationIsAKnownInput) {
  const Scenario scenario = loadScenarioFile(testing::scenarioPath("figure_eight_2d.yaml"));
  const ControllerDesign design = ControllerDesign::create(scenario.controller);
  using Dims = DoubleIntegrator2D;
  FollowerController<Dims> plain(design);
  FollowerController<Dims> turning(design);
  Dims::InputVector slot_acceleration(0.4, -0.25);
  Dims::OutputVector y(1.0, -0.5, 0.3, 0.2);
  for (int k = 0; k < 50; ++k) {
    StepInputs<Dims> inputs;
    if (k % 7 != 3) {  // every seventh a tick without a measurement: the fallback
      inputs.measurement = y;
    }
    const Dims::StateVector estimate = plain.estimate();
    ASSERT_LT((turning.estimate() - estimate).norm(), 1e-12) << k;
    const Dims::InputVector plain_command = plain.step(inputs).command;
    inputs.slot_acceleration = slot_acceleration;
    const auto& status = turning.step(inputs);
    EXPECT_LT((status.command - plain_command - slot_acceleration).norm(), 1e-12) << k;
    EXPECT_EQ(status.slot_command, slot_acceleration);
    y = 0.9 * y;
  }
  StepInputs<Dims> inputs{y};
  inputs.slot_acceleration = Dims::InputVector(std::nan(""), 0.0);
  const auto& status = turning.step(inputs);
  EXPECT_TRUE(status.slot_acceleration_rejected);
  EXPECT_TRUE(status.command.allFinite());
  EXPECT_EQ(status.slot_command, Dims::InputVector::Zero());
}

}  // namespace
}  // namespace projection_collision_avoidance
