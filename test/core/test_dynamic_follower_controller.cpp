/// DynamicFollowerController: the run-time dispatch gives the fixed-size controller's results,
/// keeps its estimate across a parameter change, and allocates nothing per step (see
/// test_no_allocation for the counting).

#include <cmath>

#include <gtest/gtest.h>

#include "projection_collision_avoidance/core/DynamicFollowerController.hpp"
#include "projection_collision_avoidance/sim/ScenarioEmbedding.hpp"

#include "EigenTestHelpers.hpp"
#include "TestScenarios.hpp"

namespace projection_collision_avoidance {
namespace {

TEST(DynamicFollowerController, MatchesTheFixedSizeController) {
  const Scenario one_axis = loadScenarioFile(testing::scenarioPath("paper_run2.yaml"));
  const Scenario planar = embedAlongDirection(one_axis, Eigen::Vector2d(0.6, 0.8));
  const ControllerDesign design = ControllerDesign::create(planar.controller);
  DynamicFollowerController runtime(design);
  FollowerController<DoubleIntegrator2D> fixed(design);
  for (int k = 0; k < 500; ++k) {
    const Eigen::Vector4d y(0.01 * k, -0.02 * k, std::sin(0.1 * k), 0.3);
    const auto& a = runtime.step(y);
    const auto& b = fixed.step(y);
    ASSERT_MATRIX_NEAR(a.command, b.command, 0.0);
    ASSERT_MATRIX_NEAR(a.estimate, b.estimate, 0.0);
    ASSERT_EQ(a.projection_active, b.projection_active);
    ASSERT_EQ(a.constraint_value, b.constraint_value);
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
    const Eigen::Vector2d y(0.02 * k - 3.0, std::sin(0.05 * k));
    const Eigen::Vector2d own_state(0.1 * k, 2.0 * std::cos(0.03 * k));
    const Eigen::Matrix<double, 1, 1> leader_input(std::sin(0.2 * k));
    const bool shared = k % 3 != 0;
    const auto& a = shared ? runtime.stepWithOwnState(y, own_state, leader_input)
                           : runtime.stepWithOwnState(y, own_state);
    const auto& b = shared ? fixed.stepWithOwnState(y, own_state, leader_input)
                           : fixed.stepWithOwnState(y, own_state);
    ASSERT_MATRIX_NEAR(a.command, b.command, 0.0);
    ASSERT_MATRIX_NEAR(a.headway_command, b.headway_command, 0.0);
    ASSERT_MATRIX_NEAR(a.feedforward_command, b.feedforward_command, 0.0);
    ASSERT_MATRIX_NEAR(a.estimate, b.estimate, 0.0);
    ASSERT_EQ(a.projection_active, b.projection_active);
  }
  EXPECT_GT(runtime.status().headway_command.norm(), 0.0);
}

TEST(DynamicFollowerController, SetDesignKeepsTheEstimateInsideTheNewBound) {
  ControllerParameters p = testing::paperParameters();
  DynamicFollowerController controller(ControllerDesign::create(p));
  for (int k = 0; k < 200; ++k) {
    controller.step(Eigen::Vector2d(6.0, 0.0));  // far outside: the estimate saturates at 4 m
  }
  EXPECT_NEAR(controller.estimate().norm(), 4.0, 1e-6);
  p.alpha = 0.5;  // xi_max = 2.5 m
  p.tracker_enabled = false;
  controller.setDesign(ControllerDesign::create(p));
  EXPECT_LE(controller.estimate().norm(), 2.5);
  EXPECT_NEAR(controller.estimate().norm(), 2.5, 1e-12);
  EXPECT_FALSE(controller.design().parameters.tracker_enabled);
  const auto& status = controller.step(Eigen::Vector2d(6.0, 0.0));
  EXPECT_TRUE(status.tracker_command.isZero());
  p.model = makeDoubleIntegrator(2);
  p.separation = Eigen::Vector4d(5.0, 0.0, 0.0, 0.0);
  EXPECT_THROW(controller.setDesign(ControllerDesign::create(
                   embedAlongDirection(loadScenarioFile(testing::scenarioPath("paper_run2.yaml")),
                                       Eigen::Vector2d(1.0, 0.0))
                       .controller)),
               std::invalid_argument);
}

}  // namespace
}  // namespace projection_collision_avoidance
