/// The follower's control cycle with formation.neighbours (doc/math.md, "Neighbours"), without
/// ROS: the first step waits for a neighbour array, a step without a fresh one brakes; with one,
/// the command is the paper's projected onto the agents' half-spaces (N3), each agent moved to the
/// step's stamp and given its perimeter (the target's alpha ||d_i||, the others' rho); the report
/// says which agent acts; a step with 64 agents allocates nothing.

#include <cmath>
#include <cstdint>
#include <cstring>
#include <memory>
#include <string>

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
constexpr double kRho = 1.0;  // m, the neighbours' perimeter

/// The V of four's controller (2-D, d = [5, 0], 100 Hz, a_max = 3 m/s^2).
ControllerDesign crowdDesign() {
  return ControllerDesign::create(
      loadScenarioFile(testing::scenarioPath("crowd_v4_gust.yaml")).controller);
}

NeighbourCycleSettings protection() {
  NeighbourCycleSettings settings;
  settings.parameters.enabled = true;
  settings.parameters.braking_acceleration = 1.0;
  settings.parameters.neighbour_acceleration = 1.0;
  settings.parameters.rate = 1.0;
  settings.perimeter = kRho;
  return settings;
}

std::unique_ptr<FollowerCycle> makeCycle(bool neighbours) {
  const ControllerDesign design = crowdDesign();
  FollowerCycleSettings settings;
  if (neighbours) {
    settings.neighbours = protection();
  }
  return std::make_unique<FollowerCycle>(std::make_unique<DynamicFollowerController>(design),
                                         design.parameters.separation, settings);
}

MeasurementSample measurementAt(std::int64_t stamp_ns, std::uint64_t sequence) {
  MeasurementSample m;
  m.stamp_ns = m.receipt_ns = stamp_ns;
  m.sequence = sequence;
  m.relative_state = GenericDimensions::StateVector(4);
  m.relative_state << 6.0, 0.5, 0.2, 0.0;  // the slot 1 m ahead, 0.5 m across: push toward +x
  return m;
}

SensedAgent agent(const char* id, double px, double py, double vx, double vy) {
  SensedAgent a;
  a.position << px, py, 0.0;  // p_j - p_i
  a.velocity << vx, vy, 0.0;  // v_j - v_i
  std::strncpy(a.id.data(), id, a.id.size() - 1);
  return a;
}

/// An array stamped @p stamp_ns: the target (the leader) 6 m ahead, follower_2 3 m ahead and
/// closing at 1 m/s, follower_3 far behind and leaving.
NeighbourSample crowdAt(std::int64_t stamp_ns, std::uint64_t sequence) {
  NeighbourSample sample;
  sample.stamp_ns = sample.receipt_ns = stamp_ns;
  sample.sequence = sequence;
  sample.agents[0] = agent("follower_2", 3.0, 0.0, -1.0, 0.0);
  sample.agents[1] = agent("leader", 6.0, 0.5, 0.2, 0.0);
  sample.agents[1].target = true;
  sample.agents[2] = agent("follower_3", -20.0, 0.0, -1.0, 0.0);
  sample.count = sample.sent = 3;
  return sample;
}

TEST(FollowerCycleNeighbours, TheFirstStepWaitsForAnArrayAndAStaleOneBrakes) {
  auto cycle = makeCycle(true);
  FollowerCycleOutput out;
  cycle->measurement().write(measurementAt(kStart, 1));
  EXPECT_FALSE(cycle->tick(kStart, 0.0, 0, &out));  // the first step waits for an array
  EXPECT_EQ(out.mode, FollowerMode::kWaiting);

  const std::int64_t t1 = kStart + 10 * kMs;
  cycle->measurement().write(measurementAt(t1, 2));
  cycle->neighbours().write(crowdAt(t1, 1));
  ASSERT_TRUE(cycle->tick(t1, 0.0, 0, &out));
  EXPECT_EQ(out.mode, FollowerMode::kTracking);
  EXPECT_TRUE(out.neighbours.fresh);
  EXPECT_FALSE(out.status.fallback);

  // The measurement stays fresh, the array does not: 0.5 s is the measurement timeout.
  const std::int64_t t2 = t1 + 510 * kMs;
  cycle->measurement().write(measurementAt(t2, 3));
  ASSERT_TRUE(cycle->tick(t2, 0.0, 0, &out));
  EXPECT_EQ(out.mode, FollowerMode::kMeasurementLost);
  EXPECT_FALSE(out.neighbours.fresh);
  EXPECT_NEAR(out.neighbours.age, 0.51, 1e-9);
  EXPECT_EQ(out.neighbours.kept, 0);
  EXPECT_TRUE(out.status.fallback);

  // After a jump back of ROS time the old array is of another timeline: none, so brake.
  const std::int64_t t3 = t1 - 100 * kMs;
  cycle->measurement().write(measurementAt(t3, 4));
  ASSERT_TRUE(cycle->tick(t3, 0.0, 0, &out));
  EXPECT_EQ(out.mode, FollowerMode::kMeasurementLost);
  EXPECT_EQ(out.neighbours.age, kNoInputAge);
  cycle->neighbours().write(crowdAt(t3 + 10 * kMs, 2));
  cycle->measurement().write(measurementAt(t3 + 10 * kMs, 5));
  ASSERT_TRUE(cycle->tick(t3 + 10 * kMs, 0.0, 0, &out));
  EXPECT_EQ(out.mode, FollowerMode::kTracking);
}

TEST(FollowerCycleNeighbours, TheCommandIsThePapersProjectedOntoTheAgentsHalfSpaces) {
  auto protected_cycle = makeCycle(true);
  auto plain_cycle = makeCycle(false);
  const ControllerDesign design = crowdDesign();
  // The same step by hand: the controller, and the half-spaces of p_i - p_j, v_i - v_j of each
  // agent moved 20 ms ahead (the array is that much older than the step).
  DynamicFollowerController controller(design);
  NeighbourConstraints constraints(protection().parameters, kRho, 2,
                                   design.parameters.acceleration_limit);
  FollowerCycleOutput out;
  FollowerCycleOutput plain;
  for (int k = 0; k < 30; ++k) {
    const std::int64_t t = kStart + 10 * k * kMs;
    protected_cycle->measurement().write(measurementAt(t, k + 1));
    plain_cycle->measurement().write(measurementAt(t, k + 1));
    const NeighbourSample crowd = crowdAt(t - 20 * kMs, k + 1);
    protected_cycle->neighbours().write(crowd);
    ASSERT_TRUE(protected_cycle->tick(t, 0.0, 0, &out));
    ASSERT_TRUE(plain_cycle->tick(t, 0.0, 0, &plain));

    constraints.clear();
    for (int j = 0; j < crowd.count; ++j) {
      const SensedAgent& a = crowd.agents[static_cast<std::size_t>(j)];
      constraints.add(-(a.position + 0.02 * a.velocity), -a.velocity,
                      a.target ? design.perimeter : kRho);
    }
    const Eigen::VectorXd y = design.parameters.model.C *
                              (measurementAt(t, 1).relative_state - design.parameters.separation);
    DynamicStepInputs inputs;
    inputs.measurement.emplace(y);
    inputs.command_constraints = &constraints.projection();
    const auto& expected = controller.step(inputs);
    ASSERT_EQ(out.status.command.size(), 2);
    EXPECT_EQ(out.status.command(0), expected.command(0)) << k;  // bit for bit
    EXPECT_EQ(out.status.command(1), expected.command(1)) << k;
  }
  // follower_2 closing at 1 m/s from 3 m (2.8 m at the stamp) binds the push toward it; the
  // leader (its own perimeter alpha ||d|| = 1 m) and follower_3 (beyond reach) do not.
  EXPECT_TRUE(out.neighbours.projected);
  EXPECT_GT((out.status.command - plain.status.command).norm(), 0.1);
  EXPECT_LT(out.status.command(0), plain.status.command(0));
  EXPECT_EQ(out.neighbours.sent, 3);
  EXPECT_EQ(out.neighbours.sensed, 3);
  EXPECT_EQ(out.neighbours.binding, 0);
  EXPECT_EQ(std::string(out.neighbours.binding_id.data()), "follower_2");
  ASSERT_EQ(out.neighbours.count, 3);
  EXPECT_EQ(out.neighbours.marks[0].role, NeighbourRole::kBinding);
  EXPECT_NE(out.neighbours.marks[1].role, NeighbourRole::kBinding);
  EXPECT_EQ(out.neighbours.marks[2].role, NeighbourRole::kSensed);       // leaving: no half-space
  EXPECT_NEAR(out.neighbours.marks[0].position.x(), 3.0 - 0.02, 1e-12);  // moved to the stamp
  EXPECT_EQ(out.neighbours.marks[0].perimeter, kRho);
  EXPECT_EQ(out.neighbours.marks[1].perimeter, design.perimeter);  // the target's own
  EXPECT_NEAR(out.neighbours.nearest, 2.98, 1e-12);
  EXPECT_EQ(out.neighbours.active, out.status.constraints_active);
}

TEST(FollowerCycleNeighbours, AFarCrowdLeavesThePapersCommandBitForBit) {
  auto protected_cycle = makeCycle(true);
  auto plain_cycle = makeCycle(false);
  FollowerCycleOutput out;
  FollowerCycleOutput plain;
  NeighbourSample far;
  far.count = far.sent = 2;
  far.agents[0] = agent("follower_2", 0.0, 30.0, 0.0, 0.0);
  far.agents[1] = agent("follower_3", 0.0, -30.0, 0.0, 0.0);
  for (int k = 0; k < 20; ++k) {
    const std::int64_t t = kStart + 10 * k * kMs;
    far.stamp_ns = far.receipt_ns = t;
    protected_cycle->neighbours().write(far);
    protected_cycle->measurement().write(measurementAt(t, k + 1));
    plain_cycle->measurement().write(measurementAt(t, k + 1));
    ASSERT_TRUE(protected_cycle->tick(t, 0.0, 0, &out));
    ASSERT_TRUE(plain_cycle->tick(t, 0.0, 0, &plain));
    EXPECT_EQ(out.status.command, plain.status.command) << k;
    EXPECT_FALSE(out.neighbours.projected);
  }
  EXPECT_FALSE(plain.neighbours.configured);
  EXPECT_EQ(out.neighbours.binding, -1);
  EXPECT_STREQ(out.neighbours.binding_id.data(), "");
}

TEST(FollowerCycleNeighbours, AStepWithSixtyFourAgentsAllocatesNothing) {
  auto cycle = makeCycle(true);
  NeighbourSample crowd;
  crowd.count = crowd.sent = NeighbourSample::kCapacity;
  for (int j = 0; j < crowd.count; ++j) {
    const double angle = 0.1 * j;
    crowd.agents[static_cast<std::size_t>(j)] =
        agent("follower_j", (2.0 + 0.05 * j) * std::cos(angle), (2.0 + 0.05 * j) * std::sin(angle),
              -std::cos(angle), -std::sin(angle));
  }
  FollowerCycleOutput out;
  for (int k = 0; k < 5; ++k) {  // warm-up
    const std::int64_t t = kStart + 10 * k * kMs;
    crowd.stamp_ns = crowd.receipt_ns = t;
    cycle->neighbours().write(crowd);
    cycle->measurement().write(measurementAt(t, k + 1));
    ASSERT_TRUE(cycle->tick(t, 0.0, 0, &out));
  }
  const long before = testing::allocationCount();
  for (int k = 5; k < 105; ++k) {
    const std::int64_t t = kStart + 10 * k * kMs;
    crowd.stamp_ns = crowd.receipt_ns = t;
    cycle->neighbours().write(crowd);
    cycle->measurement().write(measurementAt(t, k + 1));
    cycle->tick(t, 0.0, 0, &out);
  }
  EXPECT_EQ(testing::allocationCount() - before, 0);
  EXPECT_EQ(out.neighbours.sensed, 64);
  EXPECT_EQ(out.neighbours.kept, 8);  // max_neighbours
  EXPECT_TRUE(out.neighbours.projected);
}

}  // namespace
}  // namespace projection_collision_avoidance
