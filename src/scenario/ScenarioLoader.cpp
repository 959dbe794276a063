#include "projection_collision_avoidance/scenario/ScenarioLoader.hpp"

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include <yaml-cpp/yaml.h>

#include "projection_collision_avoidance/core/ControllerDesign.hpp"
#include "projection_collision_avoidance/core/ParameterError.hpp"

#include "ConfigurationSections.hpp"
#include "ControllerReader.hpp"
#include "ScenarioSections.hpp"
#include "YamlParser.hpp"
#include "YamlReader.hpp"

namespace projection_collision_avoidance {
namespace {

SignalProfile readInputProfile(detail::YamlReader& leader, Eigen::Index size) {
  SignalProfile profile;
  if (!leader.has("input")) {
    return profile;
  }
  detail::YamlReader input = leader.map("input");
  if (input.has("pulses")) {
    profile.pulses = detail::readPulses(input, "pulses", size);
  }
  if (input.has("sinusoids")) {
    profile.sinusoids = detail::readSinusoids(input, "sinusoids");
  }
  input.finish();
  return profile;
}

/// controller.leader_information.link: each key optional (0 by default).
LinkSpec readLink(detail::YamlReader& sharing) {
  detail::YamlReader section = sharing.map("link");
  LinkSpec link;
  link.configured = true;
  if (section.has("delay_periods")) {
    link.delay_periods = section.integer("delay_periods");
  }
  if (section.has("latency")) {
    link.latency = section.number("latency");
  }
  if (section.has("dropout")) {
    link.dropout = section.number("dropout");
  }
  if (section.has("seed")) {
    const int seed = section.integer("seed");
    if (seed < 0) {
      throw ParameterError(section.key("seed"),
                           "must be a whole number >= 0, got " + std::to_string(seed));
    }
    link.seed = static_cast<std::uint64_t>(seed);
  }
  section.finish();
  link.validate(std::numeric_limits<double>::quiet_NaN());  // ranges; the delay with the rate later
  return link;
}

/// Reads every key, runs the per-key checks, then @p check, then the design's derived checks.
Scenario readScenario(const YAML::Node& root, const ScenarioLoadOptions& options) {
  detail::YamlReader reader(root, "");
  Scenario scenario;
  const AgentModel model = detail::readModel(reader);
  scenario.controller = detail::readController(
      reader, model, [&](detail::YamlReader& sharing) { scenario.link = readLink(sharing); });

  detail::YamlReader leader = reader.map("leader");
  scenario.leader_initial_state = leader.vector("initial_state");
  scenario.leader_input = readInputProfile(leader, model.inputDimension());
  if (leader.has("disturbance")) {
    scenario.disturbance.pulses = detail::readPulses(leader, "disturbance", model.stateDimension());
  }
  leader.finish();

  detail::YamlReader follower = reader.map("follower");
  scenario.follower_initial_state = follower.vector("initial_state");
  follower.finish();

  detail::YamlReader simulation = reader.map("simulation");
  scenario.duration = simulation.number("duration");
  simulation.finish();

  scenario.formation = detail::readFormation(reader);
  scenario.world = detail::readWorld(reader, model.stateDimension());
  reader.finish();

  scenario.validate();
  if (options.check) {
    options.check(scenario);
  }
  ControllerDesign::create(scenario.controller);
  return scenario;
}

Scenario parseRoot(const YAML::Node& root, const std::vector<std::string>& overrides,
                   const ScenarioLoadOptions& options) {
  return detail::readRoot(root, overrides,
                          [&](const YAML::Node& tree) { return readScenario(tree, options); });
}

}  // namespace

Scenario scenarioFromYaml(const YAML::Node& root, const std::vector<std::string>& overrides,
                          const ScenarioLoadOptions& options) {
  return parseRoot(YAML::Clone(root), overrides, options);
}

Scenario parseScenario(const std::string& yaml_text, const std::vector<std::string>& overrides,
                       const ScenarioLoadOptions& options) {
  return parseRoot(detail::parseYaml(yaml_text, options.cancelled), overrides, options);
}

Scenario loadScenarioFile(const std::string& path, const std::vector<std::string>& overrides,
                          const ScenarioLoadOptions& options) {
  return parseScenario(detail::readYamlFile(path), overrides, options);
}

}  // namespace projection_collision_avoidance
