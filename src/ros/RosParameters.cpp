#include "projection_collision_avoidance/ros/RosParameters.hpp"

#include <algorithm>
#include <cstddef>
#include <sstream>

#include <ros/console.h>
#include <ros/init.h>

#include "projection_collision_avoidance/configuration/ConfigurationLoader.hpp"
#include "projection_collision_avoidance/core/ParameterError.hpp"
#include "projection_collision_avoidance/cycle/FrameNames.hpp"

namespace projection_collision_avoidance {
namespace {

/// "controller.alpha" -> "~scenario/controller/alpha".
std::string parameterName(const std::string& scenario_name, const std::string& dotted_key) {
  std::string path = dotted_key;
  std::replace(path.begin(), path.end(), '.', '/');
  return "~" + scenario_name + (path.empty() || path[0] == '(' ? "" : "/" + path);
}

std::string typeName(const XmlRpc::XmlRpcValue& value) {
  switch (value.getType()) {
    case XmlRpc::XmlRpcValue::TypeBoolean:
      return "a boolean";
    case XmlRpc::XmlRpcValue::TypeInt:
      return "an integer";
    case XmlRpc::XmlRpcValue::TypeDouble:
      return "a number";
    case XmlRpc::XmlRpcValue::TypeString:
      return "a string";
    case XmlRpc::XmlRpcValue::TypeArray:
      return "a list";
    case XmlRpc::XmlRpcValue::TypeStruct:
      return "a map";
    case XmlRpc::XmlRpcValue::TypeBase64:
      return "binary data";
    case XmlRpc::XmlRpcValue::TypeDateTime:
      return "a date";
    default:
      return "of another type";
  }
}

/// Nodes converted so far by one toYaml(), against kMaxScenarioNodes.
struct Conversion {
  std::size_t nodes = 0;
};

std::string below(const std::string& path, const std::string& element) {
  return path.empty() ? element : path + "." + element;
}

/// toYaml() of @p value at @p path (a dotted path, "" for the root) and @p depth (the lists and
/// maps it lies in). A string becomes a scalar tagged as a string, so that "0.2" or "true" is
/// not taken for a number or a boolean; binary data and dates have no place in a scenario and
/// are refused with their path. The limits of the scenario files apply: a list or map deeper
/// than kMaxScenarioDepth, or more than kMaxScenarioNodes nodes, is refused with its path.
// NOLINTNEXTLINE(misc-no-recursion): bounded by kMaxScenarioDepth
YAML::Node toYamlAt(const XmlRpc::XmlRpcValue& value, const std::string& path, std::size_t depth,
                    Conversion* conversion) {
  XmlRpc::XmlRpcValue& v = const_cast<XmlRpc::XmlRpcValue&>(value);  // XmlRpc lacks const access
  if (++conversion->nodes > kMaxScenarioNodes) {
    throw ParameterError(path, "over the node limit of a scenario (" +
                                   std::to_string(kMaxScenarioNodes) + " nodes)");
  }
  const bool collection = v.getType() == XmlRpc::XmlRpcValue::TypeArray ||
                          v.getType() == XmlRpc::XmlRpcValue::TypeStruct;
  if (collection && depth > kMaxScenarioDepth) {
    throw ParameterError(path, "nested deeper than the depth limit of a scenario (" +
                                   std::to_string(kMaxScenarioDepth) + " lists and maps)");
  }
  switch (v.getType()) {
    case XmlRpc::XmlRpcValue::TypeBoolean:
      return YAML::Node(static_cast<bool>(v));
    case XmlRpc::XmlRpcValue::TypeInt:
      return YAML::Node(static_cast<int>(v));
    case XmlRpc::XmlRpcValue::TypeDouble:
      return YAML::Node(static_cast<double>(v));
    case XmlRpc::XmlRpcValue::TypeString: {
      YAML::Node text(static_cast<std::string>(v));
      text.SetTag("!");  // as YAML tags a quoted scalar
      return text;
    }
    case XmlRpc::XmlRpcValue::TypeArray: {
      YAML::Node sequence(YAML::NodeType::Sequence);
      for (int i = 0; i < v.size(); ++i) {
        sequence.push_back(toYamlAt(v[i], below(path, std::to_string(i)), depth + 1, conversion));
      }
      return sequence;
    }
    case XmlRpc::XmlRpcValue::TypeStruct: {
      YAML::Node map(YAML::NodeType::Map);
      for (auto& entry : v) {
        conversion->nodes += 1;  // the key
        map[entry.first] = toYamlAt(entry.second, below(path, entry.first), depth + 1, conversion);
      }
      return map;
    }
    default:
      throw ParameterError(
          path, "must be a number, a string, a boolean, a list or a map, got " + typeName(value));
  }
}

}  // namespace

YAML::Node toYaml(const XmlRpc::XmlRpcValue& value) {
  Conversion conversion;
  return toYamlAt(value, "", 1, &conversion);
}

bool nodeShuttingDown() { return !ros::ok() || ros::isShuttingDown(); }

void readScenarioParameter(const ros::NodeHandle& private_nh, const std::string& name,
                           const std::function<void(const std::string& path)>& from_file,
                           const std::function<void(const YAML::Node& tree)>& from_tree) {
  XmlRpc::XmlRpcValue value;
  if (!private_nh.getParam(name, value)) {
    throw ParameterError("~" + name,
                         "missing: load a scenario file into it (<rosparam command=\"load\" "
                         "file=\"...\" ns=\"" +
                             name + "\"/>) or give its path");
  }
  try {
    if (value.getType() == XmlRpc::XmlRpcValue::TypeString) {
      from_file(static_cast<std::string>(value));
    } else if (value.getType() == XmlRpc::XmlRpcValue::TypeStruct) {
      from_tree(toYaml(value));
    } else {
      throw ParameterError("", "must be a map or a file path, got " + typeName(value));
    }
  } catch (const ParameterError& error) {
    throw ParameterError(parameterName(name, error.key()), error.reason());
  } catch (const ScenarioLoadCancelled& cancelled) {
    throw ScenarioLoadCancelled("~" + name + ": " + cancelled.what());
  }
}

void requireNodeController(const ControllerParameters& controller) {
  if (!controller.model.isDoubleIntegrator()) {
    throw ParameterError("model.type",
                         "the ROS nodes run double_integrator models (relative position and "
                         "velocity); use cf_sim for a linear model");
  }
  const double rate = controller.control_rate;
  if (!(rate >= kMinNodeRate && rate <= kMaxNodeRate)) {
    std::ostringstream reason;
    reason << "the ROS nodes run at " << kMinNodeRate << " to " << kMaxNodeRate << " Hz, got "
           << rate << "; use cf_sim for other rates";
    throw ParameterError("controller.control_rate", reason.str());
  }
}

FollowerConfiguration loadFollowerConfiguration(const ros::NodeHandle& private_nh,
                                                const std::string& name) {
  ConfigurationLoadOptions options;
  options.cancelled = nodeShuttingDown;
  options.check = [](const FollowerConfiguration& configuration) {
    requireNodeController(configuration.controller);
  };
  FollowerConfiguration configuration;
  readScenarioParameter(
      private_nh, name,
      [&](const std::string& path) {
        configuration = loadFollowerConfigurationFile(path, {}, options);
      },
      [&](const YAML::Node& tree) {
        configuration = followerConfigurationFromYaml(tree, {}, options);
      });
  return configuration;
}

std::string NodeOptionReader::frame(const std::string& key, const std::string& fallback) {
  return tfFrame(text(key, fallback));
}

bool NodeOptionReader::lookup(const std::string& key, XmlRpc::XmlRpcValue* value) const {
  return nh_.getParam(key, *value);
}

void NodeOptionReader::remember(const std::string& key, const std::string& value, bool defaulted) {
  lines_.push_back("~" + key + " = " + value + (defaulted ? " (default)" : ""));
}

double NodeOptionReader::number(const std::string& key, double fallback, double min, double max) {
  XmlRpc::XmlRpcValue value;
  double result = fallback;
  const bool present = lookup(key, &value);
  if (present) {
    if (value.getType() == XmlRpc::XmlRpcValue::TypeDouble) {
      result = static_cast<double>(value);
    } else if (value.getType() == XmlRpc::XmlRpcValue::TypeInt) {
      result = static_cast<int>(value);
    } else {
      throw ParameterError("~" + key, "must be a number, got " + typeName(value));
    }
  }
  if (!(result >= min && result <= max)) {  // also refuses NaN
    std::ostringstream reason;
    reason << "must lie in [" << min << ", " << max << "], got " << result
           << (present ? "" : " (its default): set it");
    throw ParameterError("~" + key, reason.str());
  }
  std::ostringstream text;
  text << result;
  remember(key, text.str(), !present);
  return result;
}

int NodeOptionReader::integer(const std::string& key, int fallback, int min, int max) {
  XmlRpc::XmlRpcValue value;
  int result = fallback;
  const bool present = lookup(key, &value);
  if (present) {
    if (value.getType() != XmlRpc::XmlRpcValue::TypeInt) {
      throw ParameterError("~" + key, "must be an integer, got " + typeName(value));
    }
    result = static_cast<int>(value);
  }
  if (result < min || result > max) {
    throw ParameterError("~" + key, "must lie in [" + std::to_string(min) + ", " +
                                        std::to_string(max) + "], got " + std::to_string(result) +
                                        (present ? "" : " (its default): set it"));
  }
  remember(key, std::to_string(result), !present);
  return result;
}

bool NodeOptionReader::boolean(const std::string& key, bool fallback) {
  XmlRpc::XmlRpcValue value;
  bool result = fallback;
  const bool present = lookup(key, &value);
  if (present) {
    if (value.getType() != XmlRpc::XmlRpcValue::TypeBoolean) {
      throw ParameterError("~" + key, "must be true or false, got " + typeName(value));
    }
    result = static_cast<bool>(value);
  }
  remember(key, result ? "true" : "false", !present);
  return result;
}

std::string NodeOptionReader::text(const std::string& key, const std::string& fallback) {
  XmlRpc::XmlRpcValue value;
  std::string result = fallback;
  const bool present = lookup(key, &value);
  if (present) {
    if (value.getType() != XmlRpc::XmlRpcValue::TypeString) {
      throw ParameterError("~" + key, "must be a string, got " + typeName(value));
    }
    result = static_cast<std::string>(value);
  }
  remember(key, "'" + result + "'", !present);
  return result;
}

std::vector<std::string> NodeOptionReader::textList(const std::string& key,
                                                    std::size_t max_entries) {
  XmlRpc::XmlRpcValue value;
  std::vector<std::string> result;
  const bool present = lookup(key, &value);
  if (present) {
    if (value.getType() != XmlRpc::XmlRpcValue::TypeArray) {
      throw ParameterError("~" + key, "must be a list of strings, got " + typeName(value));
    }
    if (static_cast<std::size_t>(value.size()) > max_entries) {
      throw ParameterError("~" + key, "must have at most " + std::to_string(max_entries) +
                                          " entries, got " + std::to_string(value.size()));
    }
    for (int i = 0; i < value.size(); ++i) {
      if (value[i].getType() != XmlRpc::XmlRpcValue::TypeString) {
        throw ParameterError("~" + key + "[" + std::to_string(i) + "]",
                             "must be a string, got " + typeName(value[i]));
      }
      result.push_back(static_cast<std::string>(value[i]));
    }
  }
  std::string echoed = "[";
  for (const std::string& entry : result) {
    echoed += (echoed.size() > 1 ? ", '" : "'") + entry + "'";
  }
  remember(key, echoed + "]", !present);
  return result;
}

std::vector<std::string> NodeOptionReader::mapKeys(const std::string& key) {
  XmlRpc::XmlRpcValue value;
  std::vector<std::string> keys;
  if (!lookup(key, &value)) {
    return keys;
  }
  if (value.getType() != XmlRpc::XmlRpcValue::TypeStruct) {
    throw ParameterError("~" + key, "must be a map, got " + typeName(value));
  }
  for (const auto& entry : value) {
    keys.push_back(entry.first);
  }
  return keys;  // std::map order: sorted
}

void NodeOptionReader::echo(const std::string& node_name) const {
  for (const std::string& line : lines_) {
    ROS_INFO_STREAM(node_name << ": " << line);
  }
}

void echoScenario(const std::string& node_name, const ros::NodeHandle& private_nh,
                  const std::string& name) {
  XmlRpc::XmlRpcValue value;
  if (!private_nh.getParam(name, value)) {
    return;
  }
  if (value.getType() == XmlRpc::XmlRpcValue::TypeString) {
    ROS_INFO_STREAM(node_name << ": ~" << name << " = '" << static_cast<std::string>(value)
                              << "' (scenario file)");
    return;
  }
  std::istringstream lines(YAML::Dump(toYaml(value)));
  for (std::string line; std::getline(lines, line);) {
    ROS_INFO_STREAM(node_name << ": ~" << name << ": " << line);
  }
}

/// ~clock_skew/...: the policy and its window and bound, checked by StampCorrection's rules.
StampCorrectionOptions readClockSkewOptions(NodeOptionReader& reader) {
  StampCorrectionOptions o;
  const std::string policy = reader.text("clock_skew/policy", toString(o.policy));
  bool known = false;
  for (const ClockPolicy p :
       {ClockPolicy::kStamps, ClockPolicy::kReceipt, ClockPolicy::kEstimate}) {
    if (policy == toString(p)) {
      o.policy = p;
      known = true;
    }
  }
  if (!known) {
    throw ParameterError("~clock_skew/policy",
                         "must be \"stamps\", \"receipt\" or \"estimate\", got \"" + policy + "\"");
  }
  o.window = reader.number("clock_skew/window", o.window, 1e-3, 1e6);
  o.max_offset = reader.number("clock_skew/max_offset", o.max_offset, 0.0, 1e6);
  o.max_drift_rate = reader.number("clock_skew/max_drift_rate", o.max_drift_rate, 0.0, 1.0);
  return o;
}

}  // namespace projection_collision_avoidance
