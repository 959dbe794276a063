/// DynamicFollowerController: the run-time dispatch gives the fixed-size controller's results,
/// keeps its estimate across a parameter change, and allocates nothing per step (see
/// test_no_allocation for the counting).

#include <cmath>
#include <limits>
#include <sstream>

#include <gtest/gtest.h>

#include "projection_collision_avoidance/core/DynamicFollowerController.hpp"
#include "projection_collision_avoidance/sim/ScenarioEmbedding.hpp"

#include "EigenTestHelpers.hpp"
#include "TestScenarios.hpp"

namespace projection_collision_avoidance {
namespace {

/// Expects two statuses to agree in every field: vectors and scalars to within @p tolerance,
/// flags exactly.
///
/// Guard against a field added to FollowerControllerStatus and forgotten here: the structured
/// binding below must name every non-static data member of the status, in declaration order
/// (C++17 [dcl.struct.bind]), so it stops compiling when a field is added or removed, until the
/// field is named and compared here. The comparisons use the bindings for @p a and the member
/// names for @p b, so a binding that named the wrong member (fields reordered) would compare two
/// different fields and fail. A sizeof() check would miss a flag added where the struct has
/// padding (after the trailing bools, for one).
template <typename DimsA, typename DimsB>
void expectSameStatus(const FollowerControllerStatus<DimsA>& a,
                      const FollowerControllerStatus<DimsB>& b, double tolerance) {
  const auto& [command, baseline_command, tracker_command, feedforward_command, headway_command,
               fallback_command, slot_command, estimate, estimate_norm, constraint_value,
               command_saturated, command_rate_limited, fallback, projection_active,
               boundary_correction, measurement_rejected, leader_input_rejected,
               slot_acceleration_rejected, command_overflow, estimate_held, command_projected,
               constraints_given, constraints_active, constraints_dropped, binding_barrier,
               barrier_infeasible] = a;
  EXPECT_MATRIX_NEAR(command, b.command, tolerance);
  EXPECT_MATRIX_NEAR(baseline_command, b.baseline_command, tolerance);
  EXPECT_MATRIX_NEAR(tracker_command, b.tracker_command, tolerance);
  EXPECT_MATRIX_NEAR(feedforward_command, b.feedforward_command, tolerance);
  EXPECT_MATRIX_NEAR(headway_command, b.headway_command, tolerance);
  EXPECT_MATRIX_NEAR(fallback_command, b.fallback_command, tolerance);
  EXPECT_MATRIX_NEAR(slot_command, b.slot_command, tolerance);
  EXPECT_MATRIX_NEAR(estimate, b.estimate, tolerance);
  EXPECT_NEAR(estimate_norm, b.estimate_norm, tolerance);
  EXPECT_NEAR(constraint_value, b.constraint_value, tolerance);
  EXPECT_EQ(command_saturated, b.command_saturated);
  EXPECT_EQ(command_rate_limited, b.command_rate_limited);
  EXPECT_EQ(fallback, b.fallback);
  EXPECT_EQ(projection_active, b.projection_active);
  EXPECT_NEAR(boundary_correction, b.boundary_correction, tolerance);
  EXPECT_EQ(measurement_rejected, b.measurement_rejected);
  EXPECT_EQ(leader_input_rejected, b.leader_input_rejected);
  EXPECT_EQ(slot_acceleration_rejected, b.slot_acceleration_rejected);
  EXPECT_EQ(command_overflow, b.command_overflow);
  EXPECT_EQ(estimate_held, b.estimate_held);
  EXPECT_EQ(command_projected, b.command_projected);
  EXPECT_EQ(constraints_given, b.constraints_given);
  EXPECT_EQ(constraints_active, b.constraints_active);
  EXPECT_EQ(constraints_dropped, b.constraints_dropped);
  EXPECT_EQ(binding_barrier, b.binding_barrier);
  EXPECT_EQ(barrier_infeasible, b.barrier_infeasible);
}

TEST(DynamicFollowerController, MatchesTheFixedSizeController) {
  const Scenario one_axis = loadScenarioFile(testing::scenarioPath("paper_run2.yaml"));
  const Scenario planar = embedAlongDirection(one_axis, Eigen::Vector2d(0.6, 0.8));
  const ControllerDesign design = ControllerDesign::create(planar.controller);
  DynamicFollowerController runtime(design);
  FollowerController<DoubleIntegrator2D> fixed(design);
  expectSameStatus(runtime.status(), fixed.status(), 0.0);  // before the first step
  for (int k = 0; k < 500; ++k) {
    SCOPED_TRACE(::testing::Message() << "step " << k);
    const Eigen::Vector4d y(0.01 * k, -0.02 * k, std::sin(0.1 * k), 0.3);
    const auto& a = runtime.step({y});
    const auto& b = fixed.step({y});
    expectSameStatus(a, b, 0.0);
    ASSERT_FALSE(HasFailure());
  }
  EXPECT_EQ(runtime.stateDimension(), 4);
  EXPECT_EQ(runtime.inputDimension(), 2);
}

TEST(DynamicFollowerController, OwnStateAndSharedInputMatchTheFixedSizeController) {
  // The platoon's configuration: time headway (S1), shaped feed-forward (S2).
  const ControllerDesign design = ControllerDesign::create(
      loadScenarioFile(testing::scenarioPath("platoon_run2.yaml")).controller);
  ASSERT_GT(design.parameters.time_headway, 0.0);
  DynamicFollowerController runtime(design);
  FollowerController<DoubleIntegrator1D> fixed(design);
  for (int k = 0; k < 500; ++k) {
    SCOPED_TRACE(::testing::Message() << "step " << k);
    const Eigen::Vector2d y(0.02 * k - 3.0, std::sin(0.05 * k));
    const Eigen::Vector2d own_state(0.1 * k, 2.0 * std::cos(0.03 * k));
    const Eigen::Matrix<double, 1, 1> leader_input(std::sin(0.2 * k));
    const bool shared = k % 3 != 0;
    const auto& a = shared ? runtime.step({y, leader_input, own_state})
                           : runtime.step({y, std::nullopt, own_state});
    const auto& b = shared ? fixed.step({y, leader_input, own_state})
                           : fixed.step({y, std::nullopt, own_state});
    expectSameStatus(a, b, 0.0);
    ASSERT_FALSE(HasFailure());
  }
  EXPECT_GT(runtime.status().headway_command.norm(), 0.0);
}

TEST(DynamicFollowerController, TheSlotAccelerationMatchesTheFixedSizeController) {
  const ControllerDesign design = ControllerDesign::create(
      loadScenarioFile(testing::scenarioPath("figure_eight_2d.yaml")).controller);
  DynamicFollowerController runtime(design);
  FollowerController<DoubleIntegrator2D> fixed(design);
  for (int k = 0; k < 300; ++k) {
    SCOPED_TRACE(::testing::Message() << "step " << k);
    const Eigen::Vector4d y(0.01 * k, -0.5, std::sin(0.1 * k), 0.2);
    const Eigen::Vector2d slot(std::cos(0.05 * k), std::sin(0.05 * k));
    DynamicStepInputs dynamic{y};
    StepInputs<DoubleIntegrator2D> inputs{y};
    if (k % 4 != 0) {  // u_r given on three steps of four, a step without a measurement each 7
      dynamic.slot_acceleration.emplace(slot);
      inputs.slot_acceleration = slot;
    }
    if (k % 7 == 3) {
      dynamic.measurement.reset();
      inputs.measurement.reset();
    }
    expectSameStatus(runtime.step(dynamic), fixed.step(inputs), 0.0);
    ASSERT_FALSE(HasFailure());
  }
  EXPECT_GT(runtime.status().slot_command.norm(), 0.0);
}

/// How often each condition held over a run (statuses of the run-time controller).
struct Occurrences {
  int saturated = 0;
  int rate_limited = 0;
  int fallback = 0;
  int saturated_in_fallback = 0;
  int rate_limited_in_fallback = 0;
  int measurement_rejected = 0;
  int leader_input_rejected = 0;
  int command_overflow = 0;
  int feedforward = 0;  ///< ticks with a non-zero feed-forward command
  int steps = 0;
};

/// Runs the two controllers through the same mix of tracking steps (with and without u_1),
/// fallback steps (with and without u_1) and refused inputs, expecting the same status at every
/// step; returns what occurred.
template <typename Dims>
Occurrences runMixedSequence(const ControllerDesign& design) {
  using Fixed = FollowerController<Dims>;
  DynamicFollowerController runtime(design);
  Fixed fixed(design);
  const int p = design.parameters.model.outputDimension();
  const int m = design.parameters.model.inputDimension();
  Occurrences seen;
  for (int k = 0; k < 1200; ++k) {
    SCOPED_TRACE(::testing::Message() << "step " << k);
    // Square-wave steps of the measured position error (the command jumps: saturation, then the
    // rate limit), on a slow oscillation.
    Eigen::VectorXd y(p);
    for (int i = 0; i < p; ++i) {
      y(i) = (i % 2 == 0 ? 3.0 : 0.5) * ((k / 70) % 2 == 0 ? 1.0 : -1.0) + std::sin(0.03 * k + i);
    }
    Eigen::VectorXd leader_input = Eigen::VectorXd::Constant(m, 1.5 * std::sin(0.07 * k));
    if (k == 700) {
      y(0) = std::nan("");  // refused: this tick runs the fallback
    }
    if (k == 710) {
      leader_input(0) = std::numeric_limits<double>::infinity();  // taken as unknown
    }
    if (k == 720) {
      y.setConstant(1e308);  // finite, but G y overflows: the fallback runs instead
    }
    const typename Fixed::OutputVector y_fixed = y;
    const typename Fixed::InputVector u_fixed = leader_input;
    const bool in_fallback = (k >= 300 && k < 450) || (k >= 900 && k < 960);
    const bool shared = k % 4 != 0;
    const DynamicFollowerStatus* a = nullptr;
    const FollowerControllerStatus<Dims>* b = nullptr;
    if (in_fallback) {
      a = shared ? &runtime.step({std::nullopt, leader_input}) : &runtime.step({});
      b = shared ? &fixed.step({std::nullopt, u_fixed}) : &fixed.step({});
    } else {
      a = shared ? &runtime.step({y, leader_input}) : &runtime.step({y});
      b = shared ? &fixed.step({y_fixed, u_fixed}) : &fixed.step({y_fixed});
    }
    expectSameStatus(*a, *b, 0.0);
    if (::testing::Test::HasFailure()) {
      ADD_FAILURE() << "the run-time and fixed-size statuses differ";
      return seen;
    }
    ++seen.steps;
    seen.saturated += a->command_saturated ? 1 : 0;
    seen.rate_limited += a->command_rate_limited ? 1 : 0;
    seen.fallback += a->fallback ? 1 : 0;
    seen.saturated_in_fallback += a->fallback && a->command_saturated ? 1 : 0;
    seen.rate_limited_in_fallback += a->fallback && a->command_rate_limited ? 1 : 0;
    seen.measurement_rejected += a->measurement_rejected ? 1 : 0;
    seen.leader_input_rejected += a->leader_input_rejected ? 1 : 0;
    seen.command_overflow += a->command_overflow ? 1 : 0;
    seen.feedforward += a->feedforward_command.isZero(0.0) ? 0 : 1;
  }
  return seen;
}

/// The limits and the shared input that make every branch of the tick act.
ControllerParameters withLimitsAndSharedInput(ControllerParameters p) {
  p.acceleration_limit = 2.0;  // m/s^2, below G y for |y| ~ 3 m
  p.jerk_limit = 40.0;         // m/s^3: a jump of the command takes several ticks
  p.leader_input_in_command = true;
  p.leader_input_in_estimator = true;
  return p;
}

void expectEveryBranchActed(const Occurrences& seen, const char* label) {
  std::ostringstream counts;
  counts << seen.steps << " steps: saturated " << seen.saturated << ", rate limited "
         << seen.rate_limited << ", fallback " << seen.fallback << " (saturated "
         << seen.saturated_in_fallback << ", rate limited " << seen.rate_limited_in_fallback
         << "), measurement rejected " << seen.measurement_rejected << ", leader input rejected "
         << seen.leader_input_rejected << ", command overflow " << seen.command_overflow
         << ", feed-forward " << seen.feedforward;
  ::testing::Test::RecordProperty(label, counts.str());
  SCOPED_TRACE(counts.str());
  EXPECT_EQ(seen.steps, 1200);
  EXPECT_GT(seen.saturated, 0);
  EXPECT_GT(seen.rate_limited, 0);
  EXPECT_GT(seen.fallback, 0);
  EXPECT_GT(seen.saturated_in_fallback, 0);
  EXPECT_GT(seen.rate_limited_in_fallback, 0);
  EXPECT_EQ(seen.measurement_rejected, 1);
  EXPECT_EQ(seen.leader_input_rejected, 1);
  EXPECT_EQ(seen.command_overflow, 1);
  EXPECT_GT(seen.feedforward, 0);
}

TEST(DynamicFollowerController, MatchesTheFixedSizeControllerInTheFallbackAndUnderTheLimits) {
  const ControllerDesign one_axis =
      ControllerDesign::create(withLimitsAndSharedInput(testing::paperParameters()));
  const Occurrences seen_1d = runMixedSequence<DoubleIntegrator1D>(one_axis);
  ASSERT_FALSE(HasFailure());
  expectEveryBranchActed(seen_1d, "occurrences_1d");

  Scenario planar = embedAlongDirection(loadScenarioFile(testing::scenarioPath("paper_run2.yaml")),
                                        Eigen::Vector2d(0.6, 0.8));
  planar.controller = withLimitsAndSharedInput(planar.controller);
  const Occurrences seen_2d =
      runMixedSequence<DoubleIntegrator2D>(ControllerDesign::create(planar.controller));
  ASSERT_FALSE(HasFailure());
  expectEveryBranchActed(seen_2d, "occurrences_2d");
}

TEST(DynamicFollowerController, SetDesignKeepsTheEstimateInsideTheNewBound) {
  ControllerParameters p = testing::paperParameters();
  DynamicFollowerController controller(ControllerDesign::create(p));
  FollowerController<DoubleIntegrator1D> fixed(ControllerDesign::create(p));
  for (int k = 0; k < 200; ++k) {
    SCOPED_TRACE(::testing::Message() << "step " << k);
    // far outside: the estimate saturates at 4 m
    expectSameStatus(controller.step({Eigen::Vector2d(6.0, 0.0)}),
                     fixed.step({Eigen::Vector2d(6.0, 0.0)}), 0.0);
    ASSERT_FALSE(HasFailure());
  }
  EXPECT_NEAR(controller.estimate().norm(), 4.0, 1e-6);
  p.alpha = 0.5;  // xi_max = 2.5 m
  p.tracker_enabled = false;
  p.acceleration_limit = 3.0;  // below G y: the next command saturates
  p.jerk_limit = 100.0;        // from the previous command, which adoptStateOf() keeps
  testing::changeDesign(&controller, ControllerDesign::create(p));
  // The same on a fixed-size controller: the estimate and the previous command carry over, each
  // moved into the new bound.
  FollowerController<DoubleIntegrator1D> fixed_after(ControllerDesign::create(p));
  fixed_after.adoptStateOf(fixed);
  EXPECT_LE(controller.estimate().norm(), 2.5);
  EXPECT_NEAR(controller.estimate().norm(), 2.5, 1e-12);
  EXPECT_FALSE(controller.design().parameters.tracker_enabled);
  const auto& status = controller.step({Eigen::Vector2d(6.0, 0.0)});
  EXPECT_TRUE(status.tracker_command.isZero());
  expectSameStatus(status, fixed_after.step({Eigen::Vector2d(6.0, 0.0)}), 0.0);
  EXPECT_TRUE(status.command_saturated);
  for (int k = 0; k < 50; ++k) {
    SCOPED_TRACE(::testing::Message() << "step " << k << " after adoptStateOf()");
    const Eigen::Vector2d y(-1.0, 2.0);
    if (k % 2 == 0) {
      expectSameStatus(controller.step({}), fixed_after.step({}), 0.0);
    } else {
      expectSameStatus(controller.step({y}), fixed_after.step({y}), 0.0);
    }
    ASSERT_FALSE(HasFailure());
  }
  p.model = makeDoubleIntegrator(2);
  p.separation = Eigen::Vector4d(5.0, 0.0, 0.0, 0.0);
  EXPECT_THROW(testing::changeDesign(
                   &controller, ControllerDesign::create(
                                    embedAlongDirection(
                                        loadScenarioFile(testing::scenarioPath("paper_run2.yaml")),
                                        Eigen::Vector2d(1.0, 0.0))
                                        .controller)),
               std::invalid_argument);
}

}  // namespace
}  // namespace projection_collision_avoidance
