/// The follower's control cycle with path slots (doc/math.md, "Convoys on the target's path"),
/// without ROS: the target's state is the own odometry's plus the measured relative state; the
/// first step waits for the own state; the slot is x_target − [r; r'] with r on the target's path
/// whatever the own state is; an odometry slower than the measurement is moved to its stamp; a
/// stale own state brakes; a path step allocates nothing.

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <memory>
#include <vector>

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

/// The 2-D figure eight's controller (d = [5, 0], 100 Hz) with path slots (defaults: the gap
/// 1.5 ||d|| = 7.5 m).
std::unique_ptr<FollowerCycle> makePathCycle() {
  const Scenario scenario = loadScenarioFile(testing::scenarioPath("figure_eight_2d.yaml"));
  const ControllerDesign design = ControllerDesign::create(scenario.controller);
  FollowerCycleSettings settings;
  settings.path = ConvoyParameters{};
  return std::make_unique<FollowerCycle>(std::make_unique<DynamicFollowerController>(design),
                                         design.parameters.separation, settings);
}

/// The target at time @p t_s (s) driving along +x at @p speed from the origin: [p; v].
GenericDimensions::StateVector targetAt(double t_s, double speed) {
  GenericDimensions::StateVector x(4);
  x << speed * t_s, 0.0, speed, 0.0;
  return x;
}

/// The follower's odometry: state @p own ([p; v]), its controlled point the origin.
OwnStateSample ownStateOf(std::int64_t stamp_ns, std::uint64_t sequence,
                          const GenericDimensions::StateVector& own) {
  OwnStateSample sample;
  sample.stamp_ns = sample.receipt_ns = stamp_ns;
  sample.sequence = sequence;
  sample.state = own;
  sample.controlled_position = own.head(2);
  sample.controlled_velocity = own.tail(2);
  return sample;
}

/// The measurement x_target − x_i.
MeasurementSample measurementOf(std::int64_t stamp_ns, std::uint64_t sequence,
                                const GenericDimensions::StateVector& relative) {
  MeasurementSample m;
  m.stamp_ns = m.receipt_ns = stamp_ns;
  m.sequence = sequence;
  m.relative_state = relative;
  return m;
}

/// Runs @p steps steps of a target along +x at @p speed and a follower whose odometry is
/// @p own(t) (s); returns the last output.
template <typename Own>
FollowerCycleOutput drive(FollowerCycle* cycle, int steps, double speed, Own own) {
  FollowerCycleOutput out;
  std::int64_t t = kStart;
  for (int k = 0; k < steps; ++k, t += 10 * kMs) {
    const double seconds = 0.01 * k;
    const GenericDimensions::StateVector x_own = own(seconds);
    cycle->ownState().write(ownStateOf(t, k + 1, x_own));
    cycle->measurement().write(measurementOf(t, k + 1, targetAt(seconds, speed) - x_own));
    EXPECT_TRUE(cycle->tick(t, 0.0, 0, &out)) << k;
  }
  return out;
}

TEST(FollowerCyclePath, TheFirstStepWaitsForTheOwnStateAndStartsOnThePath) {
  std::unique_ptr<FollowerCycle> cycle = makePathCycle();
  FollowerCycleOutput out;
  GenericDimensions::StateVector own(4);
  own << -7.5, 0.0, 2.0, 0.0;  // on the road, the gap behind the target, at its speed
  cycle->measurement().write(measurementOf(kStart, 1, targetAt(0.0, 2.0) - own));
  EXPECT_FALSE(cycle->tick(kStart + kMs, 0.0, 0, &out));
  EXPECT_EQ(out.mode, FollowerMode::kWaiting);
  cycle->ownState().write(ownStateOf(kStart + kMs, 1, own));
  ASSERT_TRUE(cycle->tick(kStart + 2 * kMs, 0.0, 0, &out));
  EXPECT_EQ(out.mode, FollowerMode::kTracking);
  EXPECT_TRUE(out.heading_known);
  // r(0) = P(−g) = [−7.5, 0], r'(0) = [2, 0]: D = x_target − [r; r'] = [7.5, 0, 0, 0], xi = 0.
  GenericDimensions::StateVector expected(4);
  expected << 7.5, 0.0, 0.0, 0.0;
  EXPECT_LT((out.slot - expected).norm(), 1e-12);
  EXPECT_LT(out.xi.norm(), 1e-12);
}

TEST(FollowerCyclePath, TheSlotFollowsTheTargetsPathWhateverTheOwnStateIs) {
  // Two followers behind the same target, one still at the origin, one driving beside the road:
  // the target (own + measured) and so r are the same; after 20 s at 0.5 m/s r is the gap behind.
  std::unique_ptr<FollowerCycle> resting = makePathCycle();
  std::unique_ptr<FollowerCycle> moving = makePathCycle();
  const FollowerCycleOutput a = drive(resting.get(), 2000, 0.5, [](double) {
    return GenericDimensions::StateVector::Zero(4).eval();
  });
  const FollowerCycleOutput b = drive(moving.get(), 2000, 0.5, [](double t) {
    GenericDimensions::StateVector x(4);
    x << -3.0 + 0.4 * t, 2.0, 0.4, 0.0;
    return x;
  });
  EXPECT_LT((a.slot - b.slot).norm(), 1e-9);
  GenericDimensions::StateVector gap(4);
  gap << 7.5, 0.0, 0.0, 0.0;  // D = x_target − [r; r']: r 7.5 m behind, at the target's speed
  EXPECT_LT((a.slot - gap).norm(), 1e-3);
  // xi = [r − p_i; r' − v_i] = (x_target − x_i) − D.
  GenericDimensions::StateVector own(4);
  own << -3.0 + 0.4 * 19.99, 2.0, 0.4, 0.0;
  EXPECT_LT((b.xi - ((targetAt(19.99, 0.5) - own) - b.slot)).norm(), 1e-9);
}

TEST(FollowerCyclePath, AnOdometrySlowerThanTheMeasurementIsMovedToItsStamp) {
  // The same follower driving at a constant velocity behind a target along +x: its odometry at
  // every step, or at every third one only (the steps between use the one before, moved to the
  // measurement's stamp at its velocity): the same path, the same slot.
  const auto own = [](double t) {
    GenericDimensions::StateVector x(4);
    x << -7.5 + 1.2 * t, 0.3, 1.2, 0.0;
    return x;
  };
  std::unique_ptr<FollowerCycle> every = makePathCycle();
  std::unique_ptr<FollowerCycle> third = makePathCycle();
  FollowerCycleOutput a;
  FollowerCycleOutput b;
  std::int64_t t = kStart;
  for (int k = 0; k < 500; ++k, t += 10 * kMs) {
    const double seconds = 0.01 * k;
    const GenericDimensions::StateVector relative = targetAt(seconds, 1.0) - own(seconds);
    every->ownState().write(ownStateOf(t, k + 1, own(seconds)));
    if (k % 3 == 0) {
      third->ownState().write(ownStateOf(t, k / 3 + 1, own(seconds)));
    }
    every->measurement().write(measurementOf(t, k + 1, relative));
    third->measurement().write(measurementOf(t, k + 1, relative));
    ASSERT_TRUE(every->tick(t, 0.0, 0, &a));
    ASSERT_TRUE(third->tick(t, 0.0, 0, &b));
    ASSERT_LT((a.slot - b.slot).norm(), 1e-9) << k;
  }
  EXPECT_EQ(b.mode, FollowerMode::kTracking);
}

TEST(FollowerCyclePath, WhicheverStepReadsWhichSampleTheReferenceKeepsToTheMeasuredTime) {
  // A plant publishes the odometry and the measurement of each period together; a timer step
  // may run before they arrive (it reads the period before's), after (this period's), or two
  // periods behind. The reference keeps the samples' time: a step on the samples of period j
  // gives the xi that the step on time at j gives, and a step on the same samples as the step
  // before gives the same xi again (a reference advanced a period per step would be v T ahead).
  const auto own = [](double t) {
    GenericDimensions::StateVector x(4);
    x << -7.5 + 1.2 * t, 0.3, 1.2, 0.0;
    return x;
  };
  const auto write = [&own](FollowerCycle* cycle, int j) {
    const double seconds = 0.01 * j;
    const std::int64_t stamp = kStart + j * 10 * kMs;
    cycle->ownState().write(ownStateOf(stamp, j + 1, own(seconds)));
    cycle->measurement().write(measurementOf(stamp, j + 1, targetAt(seconds, 1.0) - own(seconds)));
  };
  constexpr int kSteps = 600;
  std::unique_ptr<FollowerCycle> on_time = makePathCycle();
  std::vector<GenericDimensions::StateVector> xi_on_time;
  FollowerCycleOutput out;
  for (int k = 0; k < kSteps; ++k) {
    write(on_time.get(), k);
    ASSERT_TRUE(on_time->tick(kStart + k * 10 * kMs, 0.0, 0, &out));
    xi_on_time.push_back(out.xi);
  }
  EXPECT_GT(xi_on_time.back().norm(), 0.1);  // the follower is not on its reference
  std::unique_ptr<FollowerCycle> late = makePathCycle();
  constexpr int kBehind[] = {1, 1, 0, 1, 2, 1, 0, 0, 1, 2, 2, 1, 1, 1, 0};
  int latest = -1;
  int repeats = 0;
  double largest = 0.0;
  for (int k = 0; k < kSteps; ++k) {
    const int j = std::max(latest, k - kBehind[k % 15]);
    if (j < 0) {
      continue;
    }
    repeats += j == latest ? 1 : 0;
    if (j > latest) {
      write(late.get(), j);
      latest = j;
    }
    ASSERT_TRUE(late->tick(kStart + k * 10 * kMs, 0.0, 0, &out)) << k;
    // Exactly the same after a repeat or a step of one period; after a skipped sample r moved
    // two periods on one held r'' where the step on time changed r'' half way: O(|dr''| T^2).
    const double difference = (out.xi - xi_on_time[j]).norm();
    largest = std::max(largest, difference);
    ASSERT_LT(difference, 1e-4) << "step " << k << " on the samples of " << j;
  }
  std::printf("largest difference %.3g m\n", largest);
  EXPECT_GT(repeats, 50);
}

TEST(FollowerCyclePath, AStaleOwnStateBrakesUntilItIsBack) {
  std::unique_ptr<FollowerCycle> cycle = makePathCycle();
  FollowerCycleOutput out = drive(cycle.get(), 100, 1.0, [](double t) {
    GenericDimensions::StateVector x(4);
    x << -7.5 + t, 0.0, 1.0, 0.0;
    return x;
  });
  ASSERT_EQ(out.mode, FollowerMode::kTracking);
  // The odometry stops; the measurements go on. Past the measurement timeout (0.5 s) the target's
  // state is unknown: the step brakes (measurement lost) and the slot's reference comes to rest.
  std::int64_t t = kStart + 100 * 10 * kMs;
  GenericDimensions::StateVector own(4);
  own << -6.5, 0.0, 1.0, 0.0;
  for (int k = 0; k < 200; ++k, t += 10 * kMs) {
    cycle->measurement().write(measurementOf(t, 200 + k, targetAt(1.0 + 0.01 * k, 1.0) - own));
    ASSERT_TRUE(cycle->tick(t, 0.0, 0, &out));
    if (k < 40) {
      EXPECT_EQ(out.mode, FollowerMode::kTracking) << k;
    }
  }
  EXPECT_EQ(out.mode, FollowerMode::kMeasurementLost);
  EXPECT_FALSE(out.heading_known);
  // Back: tracking again.
  cycle->ownState().write(ownStateOf(t, 500, own));
  cycle->measurement().write(measurementOf(t, 500, targetAt(3.0, 1.0) - own));
  ASSERT_TRUE(cycle->tick(t, 0.0, 0, &out));
  EXPECT_EQ(out.mode, FollowerMode::kTracking);
  EXPECT_TRUE(out.heading_known);
}

TEST(FollowerCyclePath, APathStepAllocatesNothing) {
  std::unique_ptr<FollowerCycle> cycle = makePathCycle();
  FollowerCycleOutput out;
  GenericDimensions::StateVector own = GenericDimensions::StateVector::Zero(4);
  std::int64_t t = kStart;
  for (std::uint64_t k = 1; k <= 10; ++k, t += 10 * kMs) {
    cycle->ownState().write(ownStateOf(t, k, own));
    cycle->measurement().write(measurementOf(t, k, targetAt(0.01 * k, 1.0) - own));
    ASSERT_TRUE(cycle->tick(t, 0.0, 0, &out));
  }
  GenericDimensions::StateVector relative(4);
  const long before = testing::allocationCount();
  for (std::uint64_t k = 11; k <= 3000; ++k, t += 10 * kMs) {
    cycle->ownState().write(ownStateOf(t, k, own));
    relative = targetAt(0.01 * static_cast<double>(k), 1.0);
    relative -= own;
    cycle->measurement().write(measurementOf(t, k, relative));
    cycle->tick(t, 0.0, 0, &out);
  }
  EXPECT_EQ(testing::allocationCount() - before, 0);
  EXPECT_TRUE(out.heading_known);
}

}  // namespace
}  // namespace projection_collision_avoidance
