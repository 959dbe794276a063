#include "ConfigurationSections.hpp"

#include <cstddef>
#include <exception>
#include <initializer_list>
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "YamlParser.hpp"

namespace projection_collision_avoidance::detail {
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
    value = parseYaml(assignment.substr(equals + 1));
  } catch (const ParameterError& error) {
    throw ParameterError(key, "in the value: " + error.reason());
  }
  setAtPath(root, path, 0, value, key);
}

}  // namespace

void readNumbers(YamlReader& section, std::initializer_list<std::pair<const char*, double*>> keys) {
  for (const auto& [key, value] : keys) {
    if (section.has(key)) {
      *value = section.number(key);
    }
  }
}

void applyOverrides(YAML::Node& root, const std::vector<std::string>& overrides) {
  for (const std::string& assignment : overrides) {
    applyOverride(root, assignment);
  }
}

AgentModel readModel(YamlReader& reader) {
  YamlReader model = reader.map("model");
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

FormationSpec readFormation(YamlReader& reader) {
  FormationSpec spec;
  if (!reader.has("formation")) {
    return spec;
  }
  YamlReader formation = reader.map("formation");
  spec.configured = true;
  spec.followers = formation.integer("followers");
  if (formation.has("topology")) {
    spec.topology = parseFormationTopology(formation.string("topology"), formation.key("topology"));
  }
  if (formation.has("shape")) {
    spec.shape = parseFormationShape(formation.string("shape"), formation.key("shape"));
  }
  if (formation.has("half_angle")) {
    spec.half_angle = formation.number("half_angle");
  }
  if (formation.has("slots")) {
    spec.slots = parseSlotFrame(formation.string("slots"), formation.key("slots"));
  }
  if (formation.has("turning")) {
    YamlReader turning = formation.map("turning");
    SlotHeadingParameters& heading = spec.turning;
    readNumbers(turning, {{"natural_frequency", &heading.natural_frequency},
                          {"damping", &heading.damping},
                          {"max_yaw_rate", &heading.max_yaw_rate},
                          {"max_yaw_acceleration", &heading.max_yaw_acceleration},
                          {"min_speed", &heading.min_speed}});
    if (turning.has("reversing")) {
      heading.reversing = turning.boolean("reversing");
    }
    turning.finish();
  }
  if (formation.has("path")) {
    YamlReader path = formation.map("path");
    ConvoyParameters& convoy = spec.path;
    readNumbers(path, {{"gap_ratio", &convoy.gap_ratio},
                       {"margin_ratio", &convoy.margin_ratio},
                       {"spacing", &convoy.spacing},
                       {"retrace_width", &convoy.retrace_width},
                       {"natural_frequency", &convoy.natural_frequency},
                       {"damping", &convoy.damping},
                       {"max_acceleration", &convoy.max_acceleration},
                       {"braking_acceleration", &convoy.braking_acceleration},
                       {"target_braking", &convoy.target_braking},
                       {"catch_up_speed", &convoy.catch_up_speed}});
    if (path.has("capacity")) {
      convoy.capacity = path.integer("capacity");
    }
    path.finish();
  }
  if (formation.has("neighbours")) {
    YamlReader section = formation.map("neighbours");
    NeighbourParameters& neighbours = spec.neighbours;
    neighbours.enabled = true;
    readNumbers(section, {{"radius", &neighbours.radius},
                          {"perimeter", &neighbours.perimeter},
                          {"braking_acceleration", &neighbours.braking_acceleration},
                          {"neighbour_acceleration", &neighbours.neighbour_acceleration},
                          {"rate", &neighbours.rate}});
    if (section.has("max_neighbours")) {
      neighbours.max_neighbours = section.integer("max_neighbours");
    }
    section.finish();
  }
  formation.finish();
  return spec;
}

}  // namespace projection_collision_avoidance::detail
