#pragma once

/// @file
/// Parameter sets shared by the core tests.

#include <string>
#include <utility>

#include "projection_collision_avoidance/core/ControllerParameters.hpp"
#include "projection_collision_avoidance/core/DynamicFollowerController.hpp"
#include "projection_collision_avoidance/scenario/ScenarioLoader.hpp"

namespace projection_collision_avoidance {
namespace testing {

/// The math note's controller: 1-D double integrators, d = [5, 0], alpha = eps = 0.2,
/// G = [1, 1.4], L = -5 I, Q = I, G_e = [10, 5], S_21 = 0, 100 Hz.
inline ControllerParameters paperParameters() {
  ControllerParameters p;
  p.model = makeDoubleIntegrator(1);
  p.control_rate = 100.0;
  p.separation = Eigen::Vector2d(5.0, 0.0);
  p.alpha = 0.2;
  p.epsilon = 0.2;
  p.baseline_gain = Eigen::RowVector2d(1.0, 1.4);
  p.estimator_gain = -5.0 * Eigen::Matrix2d::Identity();
  p.lyapunov_weight = Eigen::Matrix2d::Identity();
  p.estimator_substeps = 1;
  p.tracker_enabled = true;
  p.tracker_gain = Eigen::RowVector2d(10.0, 5.0);
  p.reference_gain = Eigen::RowVector2d::Zero();
  return p;
}

inline std::string scenarioPath(const std::string& name) {
  return std::string(SCENARIO_DIR) + "/" + name;
}

/// Replaces @p controller by one of @p design that carries over its state, as the follower node
/// does on reconfiguration (DynamicFollowerController::adoptStateOf()).
inline void changeDesign(DynamicFollowerController* controller, const ControllerDesign& design) {
  DynamicFollowerController replacement(design);
  replacement.adoptStateOf(*controller);
  *controller = std::move(replacement);
}

}  // namespace testing
}  // namespace projection_collision_avoidance
