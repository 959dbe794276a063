#include "projection_collision_avoidance/scenario/ScenarioLoader.hpp"

#include <cmath>
#include <cstddef>
#include <exception>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include <yaml-cpp/yaml.h>

#include "projection_collision_avoidance/core/ControllerDesign.hpp"
#include "projection_collision_avoidance/core/ParameterError.hpp"

#include "ControllerReader.hpp"
#include "YamlParser.hpp"
#include "YamlReader.hpp"

namespace projection_collision_avoidance {
namespace {

/// Sets the entry at path[index..] below @p node. Recurses once per path element of an
/// override ("a.b.0.c"), so the depth is bounded by the length of a command-line key; the
/// scenario loader runs at start-up, never in a control step.
// NOLINTNEXTLINE(misc-no-recursion)
void setAtPath(YAML::Node node, const std::vector<std::string>& path, std::size_t index,
               const YAML::Node& value, const std::string& full_key) {
  const std::string& element = path[index];
  const bool last = index + 1 == path.size();
  if (node.IsSequence()) {
    std::size_t position = 0;
    try {
      std::size_t consumed = 0;
      position = std::stoul(element, &consumed);
      if (consumed != element.size()) {
        throw std::invalid_argument(element);
      }
    } catch (const std::exception&) {
      throw ParameterError(full_key, "'" + element + "' is not an index into a list");
    }
    if (position >= node.size()) {
      throw ParameterError(full_key, "index " + element + " is past the end of the list");
    }
    if (last) {
      node[position] = value;
    } else {
      setAtPath(node[position], path, index + 1, value, full_key);
    }
    return;
  }
  if (!node.IsMap() && !node.IsNull()) {
    throw ParameterError(full_key, "'" + element + "' is below a value that is not a map");
  }
  if (last) {
    node[element] = value;
    return;
  }
  if (!node[element].IsDefined() || node[element].IsNull()) {
    node[element] = YAML::Node(YAML::NodeType::Map);  // create the missing level
  }
  setAtPath(node[element], path, index + 1, value, full_key);
}

void applyOverride(YAML::Node& root, const std::string& assignment) {
  const std::size_t equals = assignment.find('=');
  if (equals == std::string::npos || equals == 0) {
    throw ParameterError(assignment, "an override reads key=value");
  }
  const std::string key = assignment.substr(0, equals);
  std::vector<std::string> path;
  std::stringstream stream(key);
  for (std::string element; std::getline(stream, element, '.');) {
    if (element.empty()) {
      throw ParameterError(key, "has an empty path element");
    }
    path.push_back(element);
  }
  YAML::Node value;
  try {
    value = detail::parseYaml(assignment.substr(equals + 1));
  } catch (const ParameterError& error) {
    throw ParameterError(key, "in the value: " + error.reason());
  }
  setAtPath(root, path, 0, value, key);
}

AgentModel readModel(detail::YamlReader& reader) {
  detail::YamlReader model = reader.map("model");
  const std::string type = model.string("type");
  AgentModel result;
  if (type == "double_integrator") {
    result = makeDoubleIntegrator(model.integer("dimension"));
  } else if (type == "linear") {
    const Eigen::MatrixXd A = model.matrix("A", -1, -1);
    result.A = A;
    result.B = model.matrix("B", A.rows(), -1);
    result.C = Eigen::MatrixXd::Identity(A.rows(), A.rows());
    result.position_dimension = model.integer("position_dimension");
  } else {
    throw ParameterError(model.key("type"),
                         "must be double_integrator or linear, got '" + type + "'");
  }
  if (model.has("C")) {
    result.C = model.matrix("C", -1, result.A.rows());
  }
  model.finish();
  validateAgentModel(result);
  return result;
}

/// The pulses of the list @p name; each is checked against @p size entries, so that an error
/// names the entry by its path in the file ("leader.disturbance.0.vector").
std::vector<Pulse> readPulses(detail::YamlReader& parent, const std::string& name,
                              Eigen::Index size) {
  std::vector<Pulse> pulses;
  const std::size_t count = parent.sequenceSize(name);
  for (std::size_t i = 0; i < count; ++i) {
    detail::YamlReader item = parent.item(name, i);
    Pulse pulse;
    pulse.start = item.number("start");
    pulse.end = item.number("end");
    pulse.vector = item.vector("vector");
    item.finish();
    if (!std::isfinite(pulse.start)) {
      throw ParameterError(item.key("start"), "must be finite");
    }
    if (!std::isfinite(pulse.end)) {
      throw ParameterError(item.key("end"), "must be finite");
    }
    if (!(pulse.start < pulse.end)) {
      throw ParameterError(item.key("end"), "must be later than start");
    }
    if (pulse.vector.size() != size) {
      throw ParameterError(item.key("vector"), "must have " + std::to_string(size) +
                                                   " entries, got " +
                                                   std::to_string(pulse.vector.size()));
    }
    if (!pulse.vector.allFinite()) {
      throw ParameterError(item.key("vector"), "has a non-finite entry");
    }
    pulses.push_back(pulse);
  }
  return pulses;
}

SignalProfile readInputProfile(detail::YamlReader& leader, Eigen::Index size) {
  SignalProfile profile;
  if (!leader.has("input")) {
    return profile;
  }
  detail::YamlReader input = leader.map("input");
  if (input.has("pulses")) {
    profile.pulses = readPulses(input, "pulses", size);
  }
  if (input.has("sinusoids")) {
    const std::size_t count = input.sequenceSize("sinusoids");
    for (std::size_t i = 0; i < count; ++i) {
      detail::YamlReader item = input.item("sinusoids", i);
      Sinusoid wave;
      wave.amplitude = item.vector("amplitude");
      wave.frequency = item.number("frequency");
      wave.phase = item.has("phase") ? item.number("phase") : 0.0;
      item.finish();
      profile.sinusoids.push_back(wave);
    }
  }
  input.finish();
  return profile;
}

/// Reads every key, runs the per-key checks, then @p check, then the design's derived checks.
Scenario readScenario(const YAML::Node& root, const ScenarioLoadOptions& options) {
  detail::YamlReader reader(root, "");
  Scenario scenario;
  const AgentModel model = readModel(reader);
  scenario.controller = detail::readController(reader, model, &scenario.link);

  detail::YamlReader leader = reader.map("leader");
  scenario.leader_initial_state = leader.vector("initial_state");
  scenario.leader_input = readInputProfile(leader, model.inputDimension());
  if (leader.has("disturbance")) {
    scenario.disturbance.pulses = readPulses(leader, "disturbance", model.stateDimension());
  }
  leader.finish();

  detail::YamlReader follower = reader.map("follower");
  scenario.follower_initial_state = follower.vector("initial_state");
  follower.finish();

  detail::YamlReader simulation = reader.map("simulation");
  scenario.duration = simulation.number("duration");
  simulation.finish();

  if (reader.has("formation")) {
    detail::YamlReader formation = reader.map("formation");
    FormationSpec& spec = scenario.formation;
    spec.configured = true;
    spec.followers = formation.integer("followers");
    if (formation.has("topology")) {
      spec.topology =
          parseFormationTopology(formation.string("topology"), formation.key("topology"));
    }
    if (formation.has("shape")) {
      spec.shape = parseFormationShape(formation.string("shape"), formation.key("shape"));
    }
    if (formation.has("half_angle")) {
      spec.half_angle = formation.number("half_angle");
    }
    formation.finish();
  }
  reader.finish();

  scenario.validate();
  if (options.check) {
    options.check(scenario);
  }
  ControllerDesign::create(scenario.controller);
  return scenario;
}

Scenario parseRoot(YAML::Node root, const std::vector<std::string>& overrides,
                   const ScenarioLoadOptions& options) {
  if (!root.IsMap()) {
    throw ParameterError("(root)", "a scenario is a YAML map");
  }
  try {
    for (const std::string& assignment : overrides) {
      applyOverride(root, assignment);
    }
    return readScenario(root, options);
  } catch (const YAML::Exception& error) {  // every read names its key; this is a safety net
    throw ParameterError("(root)", std::string("cannot be read: ") + error.what());
  }
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
