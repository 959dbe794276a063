/// The follower's control cycle with turning slots (doc/math.md, "Turning slots"), without ROS:
/// the heading of the target's velocity from the own odometry and the measurement; the first
/// step waits for the own state; a stale own state, a target at rest and a heading that jumps
/// every step stop or bound the slot's turn; a turning step allocates nothing.

#include <cmath>
#include <cstdint>
#include <memory>

#include <gtest/gtest.h>

#include "projection_collision_avoidance/core/ControllerDesign.hpp"
#include "projection_collision_avoidance/cycle/FollowerCycle.hpp"
#include "projection_collision_avoidance/scenario/ScenarioLoader.hpp"

#include "AllocationCounter.hpp"
#include "TestScenarios.hpp"

namespace projection_collision_avoidance {
namespace {

constexpr std::int64_t kMs = 1000000;  // ns
constexpr std::int64_t kStart = 1000 * 1000 * kMs;
constexpr double kPi = 3.141592653589793;

/// The 2-D figure eight's controller (d = [5, 0], 100 Hz) with turning slots.
std::unique_ptr<FollowerCycle> makeTurningCycle(SlotHeadingParameters turning = {}) {
  const Scenario scenario = loadScenarioFile(testing::scenarioPath("figure_eight_2d.yaml"));
  const ControllerDesign design = ControllerDesign::create(scenario.controller);
  FollowerCycleSettings settings;
  settings.turning = turning;
  return std::make_unique<FollowerCycle>(std::make_unique<DynamicFollowerController>(design),
                                         design.parameters.separation, settings);
}

/// x_target - x_i: the target @p gap m ahead along @p heading, both at @p speed along it.
MeasurementSample measurementAt(std::int64_t stamp_ns, std::uint64_t sequence, double heading,
                                double gap = 5.0) {
  MeasurementSample m;
  m.stamp_ns = m.receipt_ns = stamp_ns;
  m.sequence = sequence;
  m.relative_state.setZero(4);
  m.relative_state << gap * std::cos(heading), gap * std::sin(heading), 0.0, 0.0;
  return m;
}

/// The follower at the origin moving at @p speed along @p heading.
OwnStateSample ownStateAt(std::int64_t stamp_ns, std::uint64_t sequence, double heading,
                          double speed = 2.0) {
  OwnStateSample own;
  own.stamp_ns = own.receipt_ns = stamp_ns;
  own.sequence = sequence;
  own.state.setZero(4);
  own.state << 0.0, 0.0, speed * std::cos(heading), speed * std::sin(heading);
  own.controlled_velocity = own.state.tail(2);
  return own;
}

TEST(FollowerCycleTurning, TheFirstStepWaitsForTheOwnStateWhichSetsTheSlotHeading) {
  std::unique_ptr<FollowerCycle> cycle = makeTurningCycle();
  FollowerCycleOutput out;
  cycle->measurement().write(measurementAt(kStart, 1, kPi / 2));
  EXPECT_FALSE(cycle->tick(kStart + kMs, 0.0, 0, &out));
  EXPECT_EQ(out.mode, FollowerMode::kWaiting);
  cycle->ownState().write(ownStateAt(kStart + kMs, 1, kPi / 2));
  ASSERT_TRUE(cycle->tick(kStart + 2 * kMs, 0.0, 0, &out));
  EXPECT_EQ(out.mode, FollowerMode::kTracking);
  EXPECT_TRUE(out.heading_known);
  EXPECT_NEAR(out.slot_heading.angle, kPi / 2, 1e-12);
  // d = [5, 0] turned to +y: the follower on its slot, xi = 0.
  EXPECT_NEAR(out.slot(0), 0.0, 1e-12);
  EXPECT_NEAR(out.slot(1), 5.0, 1e-12);
  EXPECT_LT(out.xi.norm(), 1e-12);
}

TEST(FollowerCycleTurning, AStaleOwnStateOrATargetAtRestStopsTheTurn) {
  std::unique_ptr<FollowerCycle> cycle = makeTurningCycle();
  FollowerCycleOutput out;
  std::uint64_t sequence = 0;
  std::int64_t t = kStart;
  // One second of a target turning at 0.3 rad/s: the slot turns.
  for (int k = 0; k < 100; ++k, t += 10 * kMs) {
    const double heading = 0.3 * 1e-9 * static_cast<double>(t - kStart);
    cycle->measurement().write(measurementAt(t, ++sequence, heading));
    cycle->ownState().write(ownStateAt(t, sequence, heading));
    ASSERT_TRUE(cycle->tick(t, 0.0, 0, &out));
  }
  ASSERT_TRUE(out.heading_known);
  ASSERT_GT(out.slot_heading.rate, 0.1);
  // The odometry stops: once older than the measurement timeout (0.5 s) the heading is unknown
  // and the slot's turn decays; the follower keeps tracking.
  for (int k = 0; k < 300; ++k, t += 10 * kMs) {
    cycle->measurement().write(measurementAt(t, ++sequence, 0.3));
    ASSERT_TRUE(cycle->tick(t, 0.0, 0, &out));
  }
  EXPECT_EQ(out.mode, FollowerMode::kTracking);
  EXPECT_FALSE(out.heading_known);
  EXPECT_LT(std::abs(out.slot_heading.rate), 1e-3);
  // A target at rest (own velocity and relative velocity cancel): no heading either.
  OwnStateSample resting = ownStateAt(t, ++sequence, 0.0, 0.0);
  cycle->ownState().write(resting);
  cycle->measurement().write(measurementAt(t, sequence, 0.3));
  ASSERT_TRUE(cycle->tick(t, 0.0, 0, &out));
  EXPECT_FALSE(out.heading_known);
}

TEST(FollowerCycleTurning, AHeadingThatJumpsEveryStepTurnsTheSlotNoFasterThanItsBound) {
  SlotHeadingParameters turning;
  turning.max_yaw_rate = 0.5;
  std::unique_ptr<FollowerCycle> cycle = makeTurningCycle(turning);
  FollowerCycleOutput out;
  std::int64_t t = kStart;
  double previous_angle = 0.0;
  GenericDimensions::StateVector previous_slot;
  for (std::uint64_t k = 1; k <= 500; ++k, t += 10 * kMs) {
    const double heading = (k % 2 == 0) ? 0.0 : kPi * (0.9 + 0.01 * static_cast<double>(k % 7));
    cycle->measurement().write(measurementAt(t, k, 0.0));
    cycle->ownState().write(ownStateAt(t, k, heading, 50.0));
    ASSERT_TRUE(cycle->tick(t, 0.0, 0, &out));
    if (k > 1) {
      ASSERT_LE(std::abs(out.slot_heading.angle - previous_angle), 0.5 * 0.01 + 1e-12) << k;
      ASSERT_LE((out.slot - previous_slot).head(2).norm(), 5.0 * 0.5 * 0.01 + 1e-9) << k;
    }
    ASSERT_TRUE(out.status.command.allFinite());
    previous_angle = out.slot_heading.angle;
    previous_slot = out.slot;
  }
}

TEST(FollowerCycleTurning, ATurningStepAllocatesNothing) {
  std::unique_ptr<FollowerCycle> cycle = makeTurningCycle();
  FollowerCycleOutput out;
  std::int64_t t = kStart;
  for (std::uint64_t k = 1; k <= 10; ++k, t += 10 * kMs) {
    cycle->measurement().write(measurementAt(t, k, 0.1 * static_cast<double>(k)));
    cycle->ownState().write(ownStateAt(t, k, 0.1 * static_cast<double>(k)));
    ASSERT_TRUE(cycle->tick(t, 0.0, 0, &out));
  }
  const long before = testing::allocationCount();
  for (std::uint64_t k = 11; k <= 1000; ++k, t += 10 * kMs) {
    cycle->measurement().write(measurementAt(t, k, 0.01 * static_cast<double>(k)));
    cycle->ownState().write(ownStateAt(t, k, 0.01 * static_cast<double>(k)));
    cycle->tick(t, 0.0, 0, &out);
  }
  EXPECT_EQ(testing::allocationCount() - before, 0);
  EXPECT_TRUE(out.heading_known);
}

}  // namespace
}  // namespace projection_collision_avoidance
