#include "projection_collision_avoidance/ros/ScenarioParameters.hpp"

#include <string>

#include "projection_collision_avoidance/ros/RosParameters.hpp"
#include "projection_collision_avoidance/scenario/ScenarioLoader.hpp"

namespace projection_collision_avoidance {
namespace {

Scenario loadWith(const ros::NodeHandle& private_nh, const std::string& name,
                  const ScenarioLoadOptions& options) {
  Scenario scenario;
  readScenarioParameter(
      private_nh, name,
      [&](const std::string& path) { scenario = loadScenarioFile(path, {}, options); },
      [&](const YAML::Node& tree) { scenario = scenarioFromYaml(tree, {}, options); });
  return scenario;
}

}  // namespace

Scenario loadScenarioParameter(const ros::NodeHandle& private_nh, const std::string& name) {
  ScenarioLoadOptions options;
  options.cancelled = nodeShuttingDown;
  return loadWith(private_nh, name, options);
}

Scenario loadDoubleIntegratorScenario(const ros::NodeHandle& private_nh, const std::string& name) {
  ScenarioLoadOptions options;
  options.cancelled = nodeShuttingDown;
  options.check = [](const Scenario& scenario) { requireNodeController(scenario.controller); };
  return loadWith(private_nh, name, options);
}

}  // namespace projection_collision_avoidance
