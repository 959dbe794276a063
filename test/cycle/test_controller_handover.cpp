/// ControllerHandover (no master): a new design's controller offered on one thread is adopted at a
/// tick with the old one's state, and the old one is collected afterwards.

#include <memory>
#include <stdexcept>

#include <gtest/gtest.h>

#include "projection_collision_avoidance/core/ControllerDesign.hpp"
#include "projection_collision_avoidance/cycle/ControllerHandover.hpp"
#include "projection_collision_avoidance/scenario/ScenarioLoader.hpp"
#include "projection_collision_avoidance/sim/ScenarioEmbedding.hpp"

#include "TestScenarios.hpp"

namespace projection_collision_avoidance {
namespace {

std::unique_ptr<DynamicFollowerController> controllerWithAlpha(double alpha) {
  ControllerParameters p = testing::paperParameters();
  p.alpha = alpha;
  return std::make_unique<DynamicFollowerController>(ControllerDesign::create(p));
}

TEST(ControllerHandover, AdoptsTheOfferWithTheStateAndRetiresTheOld) {
  ControllerHandover handover(controllerWithAlpha(0.2));
  handover.current().step({Eigen::Vector2d(3.0, 1.0)});
  const Eigen::VectorXd estimate = handover.current().estimate();
  const Eigen::VectorXd command = handover.current().previousCommand();
  handover.adopt();  // nothing offered: nothing changes
  EXPECT_EQ(handover.retired(), nullptr);

  EXPECT_EQ(handover.offer(controllerWithAlpha(0.3)), nullptr);
  EXPECT_DOUBLE_EQ(handover.current().design().parameters.alpha, 0.2);  // not before a tick
  handover.adopt();
  EXPECT_DOUBLE_EQ(handover.current().design().parameters.alpha, 0.3);
  EXPECT_EQ(handover.current().estimate(), estimate);  // inside the new bound: unchanged
  EXPECT_EQ(handover.current().previousCommand(), command);
  const std::unique_ptr<DynamicFollowerController> old = handover.retired();
  ASSERT_NE(old, nullptr);
  EXPECT_DOUBLE_EQ(old->design().parameters.alpha, 0.2);
}

TEST(ControllerHandover, AdoptsNoMoreUntilTheRetiredOneIsCollected) {
  ControllerHandover handover(controllerWithAlpha(0.2));
  handover.offer(controllerWithAlpha(0.3));
  handover.adopt();
  handover.offer(controllerWithAlpha(0.4));
  handover.adopt();  // the 0.2 one is not collected yet
  EXPECT_DOUBLE_EQ(handover.current().design().parameters.alpha, 0.3);
  EXPECT_NE(handover.retired(), nullptr);
  handover.adopt();
  EXPECT_DOUBLE_EQ(handover.current().design().parameters.alpha, 0.4);
}

TEST(ControllerHandover, ALaterOfferReturnsTheOneNotYetAdopted) {
  ControllerHandover handover(controllerWithAlpha(0.2));
  EXPECT_EQ(handover.offer(controllerWithAlpha(0.3)), nullptr);
  const std::unique_ptr<DynamicFollowerController> returned =
      handover.offer(controllerWithAlpha(0.4));
  ASSERT_NE(returned, nullptr);
  EXPECT_DOUBLE_EQ(returned->design().parameters.alpha, 0.3);
}

TEST(ControllerHandover, RefusesNoControllerAndOtherSizes) {
  EXPECT_THROW(ControllerHandover(nullptr), std::invalid_argument);
  ControllerHandover handover(controllerWithAlpha(0.2));
  EXPECT_THROW(handover.offer(nullptr), std::invalid_argument);
  const ControllerParameters planar =
      embedAlongDirection(loadScenarioFile(testing::scenarioPath("paper_run2.yaml")),
                          Eigen::Vector2d(1.0, 0.0))
          .controller;
  EXPECT_THROW(
      handover.offer(std::make_unique<DynamicFollowerController>(ControllerDesign::create(planar))),
      std::invalid_argument);
}

}  // namespace
}  // namespace projection_collision_avoidance
