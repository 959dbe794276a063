/// A control step allocates no memory (counted by test/common/AllocationCounter.cpp).

#include <cmath>
#include <cstddef>
#include <limits>
#include <vector>

#include <Eigen/Core>
#include <gtest/gtest.h>

#include "projection_collision_avoidance/core/CommandProjection.hpp"
#include "projection_collision_avoidance/core/ControllerDesign.hpp"
#include "projection_collision_avoidance/core/ConvoyReference.hpp"
#include "projection_collision_avoidance/core/DynamicFollowerController.hpp"
#include "projection_collision_avoidance/core/FollowerController.hpp"
#include "projection_collision_avoidance/core/NeighbourBarrier.hpp"
#include "projection_collision_avoidance/sim/AgentIntegrator.hpp"
#include "projection_collision_avoidance/sim/ContinuousDynamics.hpp"
#include "projection_collision_avoidance/sim/SampledSimulator.hpp"
#include "projection_collision_avoidance/sim/ScenarioEmbedding.hpp"
#include "projection_collision_avoidance/sim/VehicleModels.hpp"
#include "projection_collision_avoidance/vehicle/CommandConverter.hpp"

#include "AllocationCounter.hpp"
#include "TestScenarios.hpp"

namespace projection_collision_avoidance {
namespace {

/// Runs @p steps control steps (each with and without the leader's input, and as many fallback
/// steps) on measurements inside and far outside the bound (so both the plain and the projected
/// drift run) and returns the allocations counted during them. @p rate_limited counts the steps
/// whose command the rate limit changed (may be null).
template <typename Dims>
long allocationsDuringSteps(const ControllerDesign& design, int steps,
                            int* rate_limited = nullptr) {
  FollowerController<Dims> controller(design);
  typename Dims::OutputVector y(design.parameters.model.outputDimension());
  typename Dims::InputVector u1(design.parameters.model.inputDimension());
  u1.setConstant(0.3);
  const long before = testing::allocationCount();
  double sink = 0.0;
  int limited = 0;
  for (int k = 0; k < steps; ++k) {
    y.setConstant((k / 50) % 2 == 0 ? 0.2 : 7.0);
    sink += controller.step({y}).command(0);
    limited += controller.status().command_rate_limited ? 1 : 0;
    sink += controller.step({y, u1}).command(0);
    limited += controller.status().command_rate_limited ? 1 : 0;
    sink += controller.step({}).command(0);
    limited += controller.status().command_rate_limited ? 1 : 0;
    sink += controller.step({std::nullopt, u1}).command(0);
    limited += controller.status().command_rate_limited ? 1 : 0;
  }
  const long after = testing::allocationCount();
  EXPECT_TRUE(std::isfinite(sink));
  if (rate_limited != nullptr) {
    *rate_limited = limited;
  }
  return after - before;
}

/// The paper's Run 2 controller in @p axes axes; @p jerk_limit in m/s^3 (infinity: none).
ControllerDesign designFor(int axes, bool share,
                           double jerk_limit = std::numeric_limits<double>::infinity()) {
  Scenario scenario = loadScenarioFile(testing::scenarioPath("paper_run2.yaml"));
  scenario.controller.estimator_substeps = 3;
  scenario.controller.leader_input_in_command = share;
  scenario.controller.leader_input_in_estimator = share;
  scenario.controller.jerk_limit = jerk_limit;
  if (axes > 1) {
    scenario = embedAlongDirection(scenario, Eigen::VectorXd::Ones(axes));
  }
  return ControllerDesign::create(scenario.controller);
}

TEST(NoAllocation, CounterSeesAllocations) {
  const long before = testing::allocationCount();
  Eigen::VectorXd heap = Eigen::VectorXd::Ones(100);
  const long after_eigen = testing::allocationCount();
  std::vector<double> vector(100, 1.0);
  const long after_vector = testing::allocationCount();
  EXPECT_GE(after_eigen - before, 1);
  EXPECT_GE(after_vector - after_eigen, 1);
  EXPECT_EQ(heap.sum() + vector.back(), 101.0);
}

TEST(NoAllocation, ControlStepsOfFixedSizeControllers) {
  for (const bool share : {false, true}) {
    EXPECT_EQ(allocationsDuringSteps<DoubleIntegrator1D>(designFor(1, share), 1000), 0);
    EXPECT_EQ(allocationsDuringSteps<DoubleIntegrator2D>(designFor(2, share), 1000), 0);
    EXPECT_EQ(allocationsDuringSteps<DoubleIntegrator3D>(designFor(3, share), 1000), 0);
  }
}

TEST(NoAllocation, ControlStepsOfTheRuntimeController) {
  for (const int axes : {1, 3}) {
    DynamicFollowerController controller(designFor(axes, true));
    Eigen::VectorXd y = Eigen::VectorXd::Constant(2 * axes, 0.2);
    const Eigen::VectorXd u1 = Eigen::VectorXd::Constant(axes, 0.3);
    controller.step({y});
    const long before = testing::allocationCount();
    for (int k = 0; k < 1000; ++k) {
      y.setConstant((k / 50) % 2 == 0 ? 0.2 : 7.0);
      controller.step({y});
      controller.step({y, u1});
      controller.step({});
      controller.step({std::nullopt, u1});
    }
    EXPECT_EQ(testing::allocationCount() - before, 0) << axes << " axes";
  }
}

TEST(NoAllocation, ControlStepsOfTheGenericController) {
  EXPECT_EQ(allocationsDuringSteps<GenericDimensions>(designFor(3, true), 1000), 0);
}

/// With the rate limit acting (5 m/s^3: 5 mm/s^2 per tick at 1 kHz) in tracking and fallback.
TEST(NoAllocation, ControlStepsWithTheRateLimitActive) {
  int limited_1d = 0;
  int limited_3d = 0;
  int limited_generic = 0;
  EXPECT_EQ(allocationsDuringSteps<DoubleIntegrator1D>(designFor(1, true, 5.0), 1000, &limited_1d),
            0);
  EXPECT_EQ(allocationsDuringSteps<DoubleIntegrator3D>(designFor(3, true, 5.0), 1000, &limited_3d),
            0);
  EXPECT_EQ(
      allocationsDuringSteps<GenericDimensions>(designFor(3, true, 5.0), 1000, &limited_generic),
      0);
  EXPECT_GT(limited_1d, 100);
  EXPECT_GT(limited_3d, 100);
  EXPECT_GT(limited_generic, 100);

  DynamicFollowerController runtime(designFor(2, true, 5.0));
  Eigen::VectorXd y = Eigen::VectorXd::Constant(4, 0.2);
  const Eigen::VectorXd u1 = Eigen::VectorXd::Constant(2, 0.3);
  runtime.step({y});
  int limited = 0;
  const long before = testing::allocationCount();
  for (int k = 0; k < 1000; ++k) {
    y.setConstant((k / 50) % 2 == 0 ? 0.2 : 7.0);
    limited += runtime.step({y, u1}).command_rate_limited ? 1 : 0;
    limited += runtime.step({std::nullopt, u1}).command_rate_limited ? 1 : 0;
  }
  EXPECT_EQ(testing::allocationCount() - before, 0);
  EXPECT_GT(limited, 100);
}

/// Allocations during evaluations of the continuous loop's right-hand side z' (evaluate()), with
/// the leader's input shared and the acceleration limit (1 m/s^2) acting; @p saturated counts
/// the evaluations whose command the limit scaled.
template <typename Dims>
long allocationsDuringEvaluations(const ControllerDesign& design, int evaluations, int* saturated) {
  const ContinuousDynamics<Dims> loop(design);
  const Eigen::Index n = design.parameters.model.stateDimension();
  typename ContinuousDynamics<Dims>::State z;
  typename ContinuousDynamics<Dims>::State derivative;
  typename ContinuousDynamics<Dims>::Signals signals;
  z.follower = Dims::StateVector::Zero(n);
  z.estimate = Dims::StateVector::Constant(n, 0.1);
  const typename Dims::InputVector u1 =
      Dims::InputVector::Constant(design.parameters.model.inputDimension(), 0.3);
  const typename Dims::StateVector ud = Dims::StateVector::Constant(n, -0.2);
  const typename Dims::StateVector separation = design.parameters.separation;
  const long before = testing::allocationCount();
  for (int k = 0; k < evaluations; ++k) {
    z.leader = separation + Dims::StateVector::Constant(n, (k % 2) * 3.0);
    loop.evaluate(z, u1, ud, &derivative, &signals);
    *saturated +=
        signals.command.norm() > design.parameters.acceleration_limit * (1.0 - 1e-12) ? 1 : 0;
  }
  return testing::allocationCount() - before;
}

TEST(NoAllocation, ContinuousLoopEvaluations) {
  for (const int axes : {1, 3}) {
    Scenario scenario = loadScenarioFile(testing::scenarioPath("paper_run2.yaml"));
    scenario.controller.leader_input_in_command = true;
    scenario.controller.leader_input_in_estimator = true;
    scenario.controller.leader_disturbance_shared = true;
    scenario.controller.acceleration_limit = 1.0;
    if (axes > 1) {
      scenario = embedAlongDirection(scenario, Eigen::VectorXd::Ones(axes));
    }
    const ControllerDesign design = ControllerDesign::create(scenario.controller);
    int saturated = 0;
    if (axes == 1) {
      EXPECT_EQ(allocationsDuringEvaluations<DoubleIntegrator1D>(design, 1000, &saturated), 0);
    } else {
      EXPECT_EQ(allocationsDuringEvaluations<DoubleIntegrator3D>(design, 1000, &saturated), 0);
      EXPECT_EQ(allocationsDuringEvaluations<GenericDimensions>(design, 1000, &saturated), 0);
    }
    EXPECT_GE(saturated, axes == 1 ? 500 : 1000) << axes << " axes";
  }
}

TEST(NoAllocation, DisturbedAgentStepsAwayFromPulseEdges) {
  const Scenario scenario = loadScenarioFile(testing::scenarioPath("paper_run2.yaml"));
  AgentIntegrator<DoubleIntegrator1D> leader(scenario.controller.model, 1e-3,
                                             scenario.leader_initial_state, scenario.disturbance);
  const DoubleIntegrator1D::InputVector input = DoubleIntegrator1D::InputVector::Constant(0.1);
  const long before = testing::allocationCount();
  for (int k = 19000; k < 24000; ++k) {  // across the pulse [20 s, 23 s), edges on ticks
    leader.advance(1e-3 * k, input);
  }
  EXPECT_EQ(testing::allocationCount() - before, 0);
  EXPECT_TRUE(leader.state().allFinite());
}

/// The simulated vehicles of the plant take commands and step without the heap.
TEST(NoAllocation, VehicleModelSteps) {
  VelocityLagParameters lag;
  lag.velocity_lag = 0.2;
  lag.max_speed = 1.0;
  VelocityLagVehicle velocity(3, Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(), lag);
  UnicycleParameters unicycle_parameters;
  unicycle_parameters.velocity_lag = 0.1;
  unicycle_parameters.max_yaw_rate = 1.0;
  UnicycleVehicle unicycle(UnicycleState{}, unicycle_parameters);
  const long before = testing::allocationCount();
  for (int k = 0; k < 1000; ++k) {
    velocity.setCommand(Eigen::Vector3d(0.01 * k, -1.0, 0.5));
    velocity.advance(0.01);
    unicycle.setCommand(1.0, 0.01 * (k % 300));
    unicycle.advance(k % 2 == 0 ? 0.01 : 0.5);
  }
  EXPECT_EQ(testing::allocationCount() - before, 0);
  EXPECT_TRUE(velocity.position().allFinite());
  EXPECT_TRUE(std::isfinite(unicycle.state().x));
}

/// A convoy follower's reference (ConvoyReference::tick(), and so TargetPath::record, at and
/// walkBack) allocates nothing after construction: rings that wrap (300 m driven), turns
/// tight enough for the goal to walk back onto the virtual road, reversals over the path, jumps
/// and a lost (NaN) target.
TEST(NoAllocation, ConvoyReferenceTicks) {
  for (const int capacity : {16, 4096}) {
    ConvoyParameters parameters;
    parameters.capacity = capacity;
    ConvoyReference reference(parameters, 0.01, 1.0);
    reference.reset(Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitX(), Eigen::Vector3d::UnitX());
    Eigen::Vector3d position = Eigen::Vector3d::Zero();
    double sink = 0.0;
    const long before = testing::allocationCount();
    for (int k = 0; k < 20000; ++k) {
      const double t = 0.01 * k;
      const int phase = (k / 1000) % 5;
      Eigen::Vector3d velocity(1.5, 0.0, 0.0);
      if (phase == 1) {  // a tight circle (radius 0.3 m)
        velocity = 1.5 * Eigen::Vector3d(std::cos(5.0 * t), std::sin(5.0 * t), 0.0);
      } else if (phase == 2) {  // back over the path
        velocity = -velocity;
      }
      position += 0.01 * velocity;
      if (k % 997 == 0) {
        position += Eigen::Vector3d(0.5, -2.0, 0.1);  // a jump
      }
      Eigen::Vector3d measured = position;
      if (phase == 3 && k % 1000 < 20) {
        measured.x() = std::numeric_limits<double>::quiet_NaN();
      }
      const ConvoySample sample = reference.tick(measured, velocity);
      sink += sample.position.sum() + sample.goal_arc +
              reference.path().walkBack(sample.progress, measured, 2.0);
    }
    EXPECT_EQ(testing::allocationCount() - before, 0) << capacity;
    EXPECT_TRUE(std::isfinite(sink));
    EXPECT_EQ(reference.path().size(), capacity);  // the ring full: it wrapped
  }
}

/// The command adapter's conversion (velocity commands brought up to date with the command
/// history, the response estimate, the unicycle map) takes odometry and commands without the heap.
TEST(NoAllocation, CommandConversions) {
  for (const bool unicycle : {false, true}) {
    CommandConverterOptions options;
    options.axes = 2;
    options.unicycle = unicycle;
    CommandConverter converter(options);
    OdometrySample own;
    const Eigen::VectorXd acceleration = Eigen::Vector2d(0.3, -0.2);
    converter.convert(acceleration, 0.0);  // the first command, before the loop
    const long before = testing::allocationCount();
    for (int k = 1; k < 1000; ++k) {
      own.stamp = 0.01 * k;
      if (k % 10 == 0) {  // a state that changes every 10 periods, republished in between
        own.linear_velocity.x() = 0.001 * k;
      }
      converter.observe(own);
      converter.convert(acceleration, own.stamp);
    }
    EXPECT_EQ(testing::allocationCount() - before, 0) << unicycle;
    EXPECT_GT(converter.response().observations, 50U);
  }
}

/// The command projection (ball and half-spaces) allocates nothing per projection: full
/// problems in 1, 2 and 3 dimensions, feasible and infeasible (the fallback drops half-spaces).
TEST(NoAllocation, CommandProjections) {
  for (const int m : {1, 2, 3}) {
    CommandProjection projection(m);
    for (int j = 0; j < CommandProjection::kMaxConstraints; ++j) {
      const double angle = 0.7 * j;
      projection.add(Eigen::Vector3d(std::cos(angle), std::sin(angle), std::cos(1.3 * j)),
                     j % 7 == 6 ? 1.5 : -0.2);  // every 7th misses the ball of radius 1
    }
    int dropped = 0;
    int changed = 0;
    const long before = testing::allocationCount();
    for (int k = 0; k < 200; ++k) {
      const Eigen::Vector3d nominal(0.03 * k - 3.0, std::sin(0.1 * k), 0.5);
      const CommandProjectionResult r = projection.project(nominal, k % 3 == 0 ? 1.0 : 2.0);
      dropped += r.dropped;
      changed += r.changed ? 1 : 0;
    }
    EXPECT_EQ(testing::allocationCount() - before, 0) << m;
    EXPECT_GT(dropped, 0) << m;
    EXPECT_GT(changed, 0) << m;
  }
}

/// The neighbours' half-spaces (N3) and a controller step projected onto them allocate nothing:
/// more neighbours than kept, some inside the perimeter, with and without a measurement.
TEST(NoAllocation, NeighbourConstraintsAndAProjectedStep) {
  NeighbourParameters parameters;
  parameters.enabled = true;
  parameters.braking_acceleration = 1.0;
  parameters.neighbour_acceleration = 1.0;
  parameters.max_neighbours = 6;
  const Scenario scenario = loadScenarioFile(testing::scenarioPath("crowd_v4_gust.yaml"),
                                             {"controller.acceleration_limit=3"});
  DynamicFollowerController controller(ControllerDesign::create(scenario.controller));
  NeighbourConstraints constraints(parameters, 1.0, 2, 3.0);
  const Eigen::VectorXd y = Eigen::Vector4d(0.3, -0.2, 0.1, 0.4);
  int projected = 0;
  const long before = testing::allocationCount();
  for (int k = 0; k < 300; ++k) {
    constraints.clear();
    for (int j = 0; j < 12; ++j) {
      const double angle = 0.5 * j + 0.01 * k;
      const Eigen::Vector3d position(std::cos(angle) * (0.5 + 0.4 * j), std::sin(angle), 0.0);
      constraints.add(position, Eigen::Vector3d(-position.x(), 0.3, 0.0), 1.0 + 0.1 * (j % 2));
    }
    DynamicStepInputs inputs;
    if (k % 5 != 4) {
      inputs.measurement.emplace(y);
    }
    inputs.command_constraints = &constraints.projection();
    projected += controller.step(inputs).command_projected ? 1 : 0;
  }
  EXPECT_EQ(testing::allocationCount() - before, 0);
  EXPECT_GT(projected, 0);
}

/// The sampled closed loop allocates while it sets up and nothing per tick: a run twice as long
/// allocates exactly as much.
TEST(NoAllocation, SampledSimulationPerTick) {
  for (const int axes : {1, 3}) {
    Scenario scenario = loadScenarioFile(testing::scenarioPath("paper_run2.yaml"));
    if (axes > 1) {
      scenario = embedAlongDirection(scenario, Eigen::VectorXd::Ones(axes));
    }
    scenario.duration = 30.0;
    const long before_short = testing::allocationCount();
    const double short_peak = simulate(scenario).max_xi;
    const long short_run = testing::allocationCount() - before_short;
    scenario.duration = 60.0;
    const long before_long = testing::allocationCount();
    const double long_peak = simulate(scenario).max_xi;
    const long long_run = testing::allocationCount() - before_long;
    EXPECT_EQ(long_run, short_run) << axes << " axes";
    EXPECT_GE(long_peak, short_peak);  // the same first 30 s, then more ticks
  }
}

}  // namespace
}  // namespace projection_collision_avoidance
