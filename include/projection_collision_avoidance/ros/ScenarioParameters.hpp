#pragma once

/// @file
/// The whole scenario (scenario/ScenarioLoader.hpp: the follower's sections and the simulation's)
/// from a node's private parameter, for the simulation nodes (plant, leader, link relay) and the
/// rostests. A follower reads its own part alone (RosParameters.hpp,
/// loadFollowerConfiguration()).

#include <string>

#include <ros/node_handle.h>

#include "projection_collision_avoidance/sim/Scenario.hpp"

namespace projection_collision_avoidance {

/// Loads the scenario from the private parameter @p name (readScenarioParameter(): a map or a
/// file's path). Errors name "~<name>/<dotted/path>". Parsing a file stops once the node shuts
/// down (SIGINT, also before ros::spin(), or ros::shutdown()).
/// @throws ParameterError for an invalid scenario or one beyond the limits of scenario files
/// @throws ScenarioLoadCancelled ("~<name>: loading cancelled at ...") when the node shut down
///         while the file was parsed
Scenario loadScenarioParameter(const ros::NodeHandle& private_nh,
                               const std::string& name = "scenario");

/// As loadScenarioParameter(), with requireNodeController() run before the controller design's
/// derived checks (as loadFollowerConfiguration() does).
Scenario loadDoubleIntegratorScenario(const ros::NodeHandle& private_nh,
                                      const std::string& name = "scenario");

}  // namespace projection_collision_avoidance
