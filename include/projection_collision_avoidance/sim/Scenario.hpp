#pragma once

#include <Eigen/Core>

#include "projection_collision_avoidance/core/ControllerParameters.hpp"
#include "projection_collision_avoidance/core/FollowerConfiguration.hpp"
#include "projection_collision_avoidance/core/Formation.hpp"
#include "projection_collision_avoidance/sim/SharedLink.hpp"
#include "projection_collision_avoidance/sim/SignalProfile.hpp"
#include "projection_collision_avoidance/sim/WorldSpec.hpp"

namespace projection_collision_avoidance {

/// A leader-follower run: the follower's controller parameters, both agents' initial states,
/// the leader's input and disturbance, and the duration. Loaded from the YAML format of
/// README.md, "Scenario files" by loadScenarioFile() (scenario library).
struct Scenario {
  ControllerParameters controller;
  Eigen::VectorXd leader_initial_state;    ///< x_1(0), n
  Eigen::VectorXd follower_initial_state;  ///< x_2(0), n
  SignalProfile leader_input;              ///< u_1(t), m; sampled at each control tick
  SignalProfile disturbance;               ///< u_d(t), n; x_1' = A x_1 + B u_1 + u_d
  double duration = 0.0;                   ///< s
  FormationSpec formation;                 ///< the followers; one ("follower") by default
  /// The link of the shared accelerations (controller.leader_information.link); a sampled run
  /// models it, the ROS nodes have a real one.
  LinkSpec link;
  /// A world that can hurt the followers (section `world`): simulation only, ignored by the
  /// nodes' controllers.
  WorldSpec world;

  /// Checks the parts that ControllerDesign::create() does not: initial states, signals and
  /// duration, formation and link. Throws ParameterError naming "leader.*", "follower.*",
  /// "simulation.duration", "formation.*", "world.*" or "controller.leader_information.link[.*]" (a
  /// link that carries nothing: neither command nor estimator shared).
  void validate() const;

  /// The followers' part of the scenario: the controller and the formation.
  FollowerConfiguration followerConfiguration() const { return {controller, formation}; }
};

}  // namespace projection_collision_avoidance
