/// The neighbours' barrier (N1)-(N2), their half-spaces in priority order (N3), and the
/// controller's command projected onto them (no roscore).

#include <cmath>
#include <limits>
#include <random>
#include <string>

#include <Eigen/Core>
#include <gtest/gtest.h>

#include "projection_collision_avoidance/core/ControllerDesign.hpp"
#include "projection_collision_avoidance/core/FollowerController.hpp"
#include "projection_collision_avoidance/core/NeighbourBarrier.hpp"
#include "projection_collision_avoidance/core/ParameterError.hpp"

#include "TestScenarios.hpp"

namespace projection_collision_avoidance {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

NeighbourParameters parameters() {
  NeighbourParameters p;
  p.enabled = true;
  p.braking_acceleration = 1.5;
  p.neighbour_acceleration = 0.5;
  p.rate = 0.8;
  return p;
}

/// h of (N1) at relative position p and velocity v (first two entries).
double barrierAt(const Eigen::Vector3d& p, const Eigen::Vector3d& v, double a_b, double rho) {
  const double c = p.norm();
  return std::sqrt(2.0 * a_b * (c - rho)) + p.dot(v) / c;
}

TEST(NeighbourBarrier, MeetingTheBoundMakesHFallNoFasterThanOmegaH) {
  // For random states outside the perimeter and a command on the bound, the neighbour
  // accelerating toward i at A_n: dh/dt (central difference along the motion) >= -omega h.
  const NeighbourParameters p = parameters();
  const double rho = 1.0;
  std::mt19937 random(3);
  std::uniform_real_distribution<double> uniform(-4.0, 4.0);
  int checked = 0;
  for (int trial = 0; trial < 2000; ++trial) {
    Eigen::Vector3d position(uniform(random), uniform(random), 0.0);
    const Eigen::Vector3d velocity(uniform(random), uniform(random), 0.0);
    if (position.norm() < rho + 0.2) {
      continue;
    }
    const NeighbourConstraint constraint = neighbourBarrier(position, velocity, p, rho);
    EXPECT_NEAR(constraint.barrier, barrierAt(position, velocity, 1.5, rho), 1e-12);
    EXPECT_NEAR(constraint.normal.norm(), 1.0, 1e-15);
    // a_i = b n + (any tangential part), a_j = A_n n toward i: relative a = (b - A_n) n + t.
    const Eigen::Vector3d tangent(-constraint.normal.y(), constraint.normal.x(), 0.0);
    const Eigen::Vector3d relative_acceleration =
        (constraint.bound - p.neighbour_acceleration) * constraint.normal + 0.7 * tangent;
    const double dt = 1e-6;
    auto hAt = [&](double t) {
      return barrierAt(position + velocity * t + 0.5 * relative_acceleration * t * t,
                       velocity + relative_acceleration * t, 1.5, rho);
    };
    const double rate = (hAt(dt) - hAt(-dt)) / (2.0 * dt);
    EXPECT_NEAR(rate, -p.rate * constraint.barrier, 1e-5 * (1.0 + std::abs(rate))) << trial;
    ++checked;
  }
  EXPECT_GT(checked, 1000);
}

TEST(NeighbourBarrier, InsideThePerimeterPushesApartAtTheWholeBudget) {
  const NeighbourParameters p = parameters();
  const NeighbourConstraint inside =
      neighbourBarrier(Eigen::Vector3d(0.0, -0.5, 0.0), Eigen::Vector3d(3.0, 1.0, 0.0), p, 1.0);
  EXPECT_EQ(inside.barrier, -kInf);
  EXPECT_DOUBLE_EQ(inside.bound, 1.5 + 0.5);
  EXPECT_EQ(inside.normal, Eigen::Vector3d(0.0, -1.0, 0.0));
  const NeighbourConstraint same_place =
      neighbourBarrier(Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(), p, 1.0);
  EXPECT_EQ(same_place.normal, Eigen::Vector3d::UnitX());
}

TEST(NeighbourBarrier, ASafeBarrierAsksNoMoreThanTheBudget) {
  // h >= 0 means s <= sqrt(2 a_b (c - rho)): then b <= a_b + A_n, which the acceleration limit
  // covers (validate()), so a single neighbour never makes the problem infeasible.
  const NeighbourParameters p = parameters();
  std::mt19937 random(5);
  std::uniform_real_distribution<double> uniform(-6.0, 6.0);
  for (int trial = 0; trial < 5000; ++trial) {
    const Eigen::Vector3d position(uniform(random), uniform(random), uniform(random));
    const Eigen::Vector3d velocity(uniform(random), uniform(random), uniform(random));
    const NeighbourConstraint c = neighbourBarrier(position, velocity, p, 1.0);
    if (c.barrier >= 0.0) {
      EXPECT_LE(c.bound, 1.5 + 0.5 + 1e-12);
    }
  }
}

TEST(NeighbourConstraints, KeepTheMostUrgentWithinTheRadiusAndCapacity) {
  NeighbourParameters p = parameters();
  p.radius = 10.0;
  p.max_neighbours = 2;
  NeighbourConstraints constraints(p, 1.0, 2, 4.0);
  const Eigen::Vector3d still = Eigen::Vector3d::Zero();
  constraints.add(Eigen::Vector3d(0.0, 8.0, 0.0), Eigen::Vector3d(0.0, -3.0, 0.0));   // closing
  constraints.add(Eigen::Vector3d(20.0, 0.0, 0.0), Eigen::Vector3d(-9.0, 0.0, 0.0));  // too far
  constraints.add(Eigen::Vector3d(0.5, 0.0, 0.0), still);                             // inside
  constraints.add(Eigen::Vector3d(-3.0, 0.0, 0.0), Eigen::Vector3d(-1.0, 0.0, 0.0));  // leaving
  constraints.add(Eigen::Vector3d(NAN, 0.0, 0.0), still);
  EXPECT_EQ(constraints.sensed(), 3);
  EXPECT_EQ(constraints.rejected(), 1);
  EXPECT_DOUBLE_EQ(constraints.nearest(), 0.5);
  EXPECT_EQ(constraints.smallestBarrier(), -kInf);
  // the leaving one asks nothing a limited command could violate (b <= -a_max) and is left out;
  // the inside one comes first, then the closing one
  ASSERT_EQ(constraints.kept(), 2);
  EXPECT_EQ(constraints.constraint(0).source, 2);  // the third add(): inside
  EXPECT_EQ(constraints.constraint(1).source, 0);  // the first: closing
  EXPECT_DOUBLE_EQ(constraints.constraint(0).distance, 0.5);
  const CommandProjection& projection = constraints.projection();
  ASSERT_EQ(projection.size(), 2);
  const CommandProjectionResult result = projection.project(Eigen::Vector3d::Zero(), 4.0);
  EXPECT_TRUE(result.changed);
  EXPECT_GE(result.command.x(), 1.5 + 0.5 - 1e-9);  // pushed away from the inside one (+x)
  constraints.clear();
  EXPECT_EQ(constraints.kept(), 0);
  EXPECT_EQ(constraints.projection().size(), 0);
  constraints.add(Eigen::Vector3d(0.5, 0.0, 0.0), still);  // the sources count afresh
  ASSERT_EQ(constraints.kept(), 1);
  EXPECT_EQ(constraints.constraint(0).source, 0);
}

TEST(NeighbourParameters, EachBadValueIsRefusedByName) {
  auto keyOf = [](NeighbourParameters p, double limit = kInf) -> std::string {
    try {
      p.validate(limit);
    } catch (const ParameterError& error) {
      return error.key();
    }
    return "";
  };
  NeighbourParameters p = parameters();
  EXPECT_EQ(keyOf(p), "");
  EXPECT_EQ(keyOf(p, 2.0), "");  // a_b + A_n = a_max: allowed
  EXPECT_EQ(keyOf(p, 1.9), "formation.neighbours.braking_acceleration");
  p.radius = 0.0;
  EXPECT_EQ(keyOf(p), "formation.neighbours.radius");
  p = parameters();
  p.perimeter = -1.0;
  EXPECT_EQ(keyOf(p), "formation.neighbours.perimeter");
  p = parameters();
  p.braking_acceleration = NAN;
  EXPECT_EQ(keyOf(p), "formation.neighbours.braking_acceleration");
  p = parameters();
  p.neighbour_acceleration = -0.1;
  EXPECT_EQ(keyOf(p), "formation.neighbours.neighbour_acceleration");
  p = parameters();
  p.rate = 0.0;
  EXPECT_EQ(keyOf(p), "formation.neighbours.rate");
  p = parameters();
  p.max_neighbours = 33;
  EXPECT_EQ(keyOf(p), "formation.neighbours.max_neighbours");
}

/// A planar paper controller with an acceleration limit of 3 m/s^2.
FollowerController<DoubleIntegrator2D> planarController() {
  ControllerParameters p = testing::paperParameters();
  p.model = makeDoubleIntegrator(2);
  p.separation = Eigen::Vector4d(5.0, 0.0, 0.0, 0.0);
  p.baseline_gain =
      doubleIntegratorGain(Eigen::Vector2d(1.0, 1.0), Eigen::Vector2d(0.7, 0.7), "baseline");
  p.estimator_gain = -5.0 * Eigen::Matrix4d::Identity();
  p.lyapunov_weight = Eigen::Matrix4d::Identity();
  p.tracker_gain =
      doubleIntegratorGain(Eigen::Vector2d(3.0, 3.0), Eigen::Vector2d(0.8, 0.8), "tracker");
  p.reference_gain = Eigen::Matrix<double, 2, 4>::Zero();
  p.fallback_gain = doubleIntegratorFallbackGain(2, 1.0);
  p.acceleration_limit = 3.0;
  return FollowerController<DoubleIntegrator2D>(ControllerDesign::create(p));
}

TEST(FollowerControllerWithNeighbours, ProjectsTheCommandAndTellsTheEstimatorWhatActs) {
  FollowerController<DoubleIntegrator2D> free = planarController();
  FollowerController<DoubleIntegrator2D> constrained = planarController();
  CommandProjection empty(2);
  CommandProjection wall(2);
  wall.add(Eigen::Vector3d(0.0, 1.0, 0.0), 1.0);  // u_y >= 1
  StepInputs<DoubleIntegrator2D> inputs;
  inputs.measurement = Eigen::Vector4d(0.5, -0.4, 0.1, 0.0);
  // No half-space: the same command and status, bit for bit.
  inputs.command_constraints = &empty;
  const Eigen::Vector2d unconstrained = free.step(inputs).command;
  EXPECT_EQ(constrained.step(inputs).command, unconstrained);
  EXPECT_FALSE(constrained.status().command_projected);
  // The wall moves the command onto u_y = 1; the estimates part from there.
  inputs.command_constraints = &wall;
  const auto& status = constrained.step(inputs);
  inputs.command_constraints = nullptr;
  const Eigen::Vector2d next_free = free.step(inputs).command;
  ASSERT_LT(next_free.y(), 1.0);
  EXPECT_TRUE(status.command_projected);
  EXPECT_EQ(status.constraints_given, 1);
  EXPECT_EQ(status.constraints_active, 1);
  EXPECT_EQ(status.constraints_dropped, 0);
  EXPECT_NEAR(status.command.y(), 1.0, 1e-12);
  EXPECT_NEAR(status.command.x(), next_free.x(), 1e-12);
  EXPECT_NE(constrained.estimate(), free.estimate());
  // Squeezed: u_y >= 1 and u_y <= -1 cannot both hold; the second is dropped.
  CommandProjection squeeze(2);
  squeeze.add(Eigen::Vector3d(0.0, 1.0, 0.0), 1.0);
  squeeze.add(Eigen::Vector3d(0.0, -1.0, 0.0), 1.0);
  inputs.command_constraints = &squeeze;
  const auto& squeezed = constrained.step(inputs);
  EXPECT_EQ(squeezed.constraints_dropped, 1);
  EXPECT_GE(squeezed.command.y(), 1.0 - 1e-9);
  EXPECT_LE(squeezed.command.norm(), 3.0 + 1e-12);
  // Without a measurement (the fallback) the half-spaces still act.
  inputs.measurement.reset();
  inputs.command_constraints = &wall;
  const auto& braking = constrained.step(inputs);
  EXPECT_TRUE(braking.fallback);
  EXPECT_GE(braking.command.y(), 1.0 - 1e-9);
}

}  // namespace
}  // namespace projection_collision_avoidance
