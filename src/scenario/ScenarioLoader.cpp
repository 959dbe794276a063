#include "projection_collision_avoidance/ScenarioLoader.hpp"

#include <cmath>
#include <cstddef>
#include <exception>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include <yaml-cpp/yaml.h>

#include "projection_collision_avoidance/ControllerDesign.hpp"
#include "projection_collision_avoidance/ParameterError.hpp"

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

/// natural_frequency or damping: one value per axis (or one number for all), each positive.
void requirePositivePerAxis(const std::string& key, const Eigen::VectorXd& values, int axes) {
  if (values.size() != axes) {
    throw ParameterError(key, "must be one number or one per axis (" + std::to_string(axes) +
                                  "), got " + std::to_string(values.size()));
  }
  for (Eigen::Index i = 0; i < values.size(); ++i) {
    if (!(std::isfinite(values(i)) && values(i) > 0.0)) {
      throw ParameterError(key, "must be positive and finite, got " + std::to_string(values(i)));
    }
  }
}

Eigen::MatrixXd readGain(detail::YamlReader& section, const AgentModel& model) {
  const bool matrix_form = section.has("gain");
  const bool pole_form = section.has("natural_frequency") || section.has("damping");
  if (matrix_form && pole_form) {
    throw ParameterError(section.key("gain"),
                         "give either gain or natural_frequency/damping, not both");
  }
  if (!pole_form) {
    return section.matrix("gain", model.inputDimension(), model.outputDimension());
  }
  if (!model.isDoubleIntegrator() || !model.C.isIdentity(0.0)) {
    throw ParameterError(section.key("natural_frequency"),
                         "needs a double_integrator model with C = identity; give gain instead");
  }
  const int axes = model.double_integrator_axes;
  const Eigen::VectorXd omega = section.vectorOrScalar("natural_frequency", axes);
  const Eigen::VectorXd zeta = section.vectorOrScalar("damping", axes);
  requirePositivePerAxis(section.key("natural_frequency"), omega, axes);
  requirePositivePerAxis(section.key("damping"), zeta, axes);
  return doubleIntegratorGain(omega, zeta, section.key("natural_frequency"));
}

ControllerParameters readController(detail::YamlReader& reader, const AgentModel& model) {
  const Eigen::Index n = model.stateDimension();
  const Eigen::Index m = model.inputDimension();
  const Eigen::Index p = model.outputDimension();
  detail::YamlReader controller = reader.map("controller");
  ControllerParameters result;
  result.model = model;
  result.control_rate = controller.number("control_rate");
  result.separation = controller.vector("separation");
  result.alpha = controller.number("alpha");
  result.epsilon = controller.number("epsilon");

  detail::YamlReader baseline = controller.map("baseline");
  result.baseline_gain = readGain(baseline, model);
  baseline.finish();

  detail::YamlReader estimator = controller.map("estimator");
  result.estimator_gain = estimator.matrix("gain", n, p);
  result.lyapunov_weight = estimator.matrix("lyapunov_weight", n, n);
  if (estimator.has("substeps")) {
    result.estimator_substeps = estimator.integer("substeps");
  }
  if (estimator.has("initial_estimate")) {
    const std::string mode = estimator.string("initial_estimate");
    if (mode == "measurement") {
      result.initial_estimate = InitialEstimate::kMeasurement;
    } else if (mode == "zero") {
      result.initial_estimate = InitialEstimate::kZero;
    } else {
      throw ParameterError(estimator.key("initial_estimate"),
                           "must be measurement or zero, got '" + mode + "'");
    }
  }
  estimator.finish();

  detail::YamlReader tracker = controller.map("tracker");
  result.tracker_enabled = tracker.boolean("enabled");
  result.tracker_gain = readGain(tracker, model);
  result.reference_gain = tracker.has("reference_gain") ? tracker.matrix("reference_gain", m, p)
                                                        : Eigen::MatrixXd::Zero(m, p);
  tracker.finish();

  if (controller.has("acceleration_limit")) {
    result.acceleration_limit = controller.number("acceleration_limit");
  }
  if (controller.has("jerk_limit")) {
    result.jerk_limit = controller.number("jerk_limit");
  }
  if (controller.has("fallback")) {
    detail::YamlReader fallback = controller.map("fallback");
    if (fallback.has("gain") && fallback.has("velocity_gain")) {
      throw ParameterError(fallback.key("gain"), "give gain or velocity_gain, not both");
    }
    if (fallback.has("gain")) {
      result.fallback_gain = fallback.matrix("gain", m, n);
    } else if (fallback.has("velocity_gain")) {
      if (!model.isDoubleIntegrator()) {
        throw ParameterError(fallback.key("velocity_gain"),
                             "needs a double_integrator model; give gain instead");
      }
      result.fallback_gain = doubleIntegratorFallbackGain(model.double_integrator_axes,
                                                          fallback.number("velocity_gain"));
    }
    fallback.finish();
  }
  if (controller.has("leader_information")) {
    detail::YamlReader sharing = controller.map("leader_information");
    if (sharing.has("command")) {
      result.leader_input_in_command = sharing.boolean("command");
    }
    if (sharing.has("estimator")) {
      result.leader_input_in_estimator = sharing.boolean("estimator");
    }
    if (sharing.has("disturbance")) {
      result.leader_disturbance_shared = sharing.boolean("disturbance");
    }
    sharing.finish();
  }
  controller.finish();
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
  scenario.controller = readController(reader, model);

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
