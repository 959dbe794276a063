#pragma once

/// @file
/// Reading a node's private parameters: the follower's configuration (the scenario file of
/// cf_sim; the simulation nodes read all of it through ScenarioParameters.hpp) and the node's own
/// options. Every failure is a ParameterError whose key is the parameter's name
/// ("~scenario/controller/alpha", "~measurement_timeout").

#include <functional>
#include <string>
#include <vector>

#include <ros/node_handle.h>
#include <xmlrpcpp/XmlRpcValue.h>
#include <yaml-cpp/yaml.h>

#include "projection_collision_avoidance/core/ControllerParameters.hpp"
#include "projection_collision_avoidance/core/FollowerConfiguration.hpp"
#include "projection_collision_avoidance/cycle/StampCorrection.hpp"

namespace projection_collision_avoidance {

/// Control rates (Hz) the ROS nodes run at: the range of the plant's and the leader's ~rate.
/// ROS timers do not keep up beyond it, and below it the nodes' timeouts make no sense.
constexpr double kMinNodeRate = 1.0;
constexpr double kMaxNodeRate = 10000.0;

/// The same tree as YAML: structs become maps, arrays sequences, scalars scalars. A string
/// becomes a scalar tagged as a string (like a quoted one), which the scenario loader does not
/// take for a number or a boolean. The limits of scenario files apply (kMaxScenarioDepth,
/// kMaxScenarioNodes of ConfigurationLoader.hpp; the root counts as depth 1, a key as a node).
/// @throws ParameterError (key: the entry's dotted path) for binary data, a date, a list or map
///         nested deeper than kMaxScenarioDepth, or the node beyond kMaxScenarioNodes
YAML::Node toYaml(const XmlRpc::XmlRpcValue& value);

/// Runs @p from_file on the path, or @p from_tree on the map, that the private parameter @p name
/// holds: a scenario file's path, or the file loaded with `<rosparam command="load"
/// file="..." ns="scenario"/>` inside the node (converted by toYaml()). A ParameterError of
/// theirs is renamed "~<name>/<dotted/path>", a ScenarioLoadCancelled "~<name>: ...".
/// @throws ParameterError when the parameter is missing or neither a string nor a map
void readScenarioParameter(const ros::NodeHandle& private_nh, const std::string& name,
                           const std::function<void(const std::string& path)>& from_file,
                           const std::function<void(const YAML::Node& tree)>& from_tree);

/// True once the node is shutting down (SIGINT, rosnode kill, ros::shutdown()): the predicate
/// that ends a scenario load still parsing. Before ros::spin() too: roscpp's poll thread turns
/// the SIGINT into ros::shutdown(), which clears ros::ok().
bool nodeShuttingDown();

/// The ROS nodes' own requirements of a controller (ROS-free): a double_integrator model, since
/// the nodes exchange relative positions and velocities, and a control rate in
/// [kMinNodeRate, kMaxNodeRate].
/// @throws ParameterError with the dotted key "model.type" or "controller.control_rate"
void requireNodeController(const ControllerParameters& controller);

/// A follower's configuration (configuration/ConfigurationLoader.hpp: the model, controller and
/// formation sections) from the private parameter @p name, as readScenarioParameter() reads it,
/// with requireNodeController() run before the controller design's derived checks, so that a
/// model or a rate the nodes refuse is named ("~<name>/model/type",
/// "~<name>/controller/control_rate") rather than a gain or "estimator/substeps" that the design
/// derives from it. Parsing a file stops once the node shuts down.
/// @throws ParameterError for an invalid configuration or one beyond the limits of scenario files
/// @throws ScenarioLoadCancelled ("~<name>: loading cancelled at ...") when the node shut down
///         while the file was parsed
FollowerConfiguration loadFollowerConfiguration(const ros::NodeHandle& private_nh,
                                                const std::string& name = "scenario");

/// Reads a node's own private options, checks each once, and remembers them for echo().
class NodeOptionReader {
 public:
  explicit NodeOptionReader(const ros::NodeHandle& private_nh) : nh_(private_nh) {}

  /// A number in [min, max]; @p fallback when absent. An int parameter is accepted.
  double number(const std::string& key, double fallback, double min, double max);
  /// A whole number in [min, max]; @p fallback when absent.
  int integer(const std::string& key, int fallback, int min, int max);
  bool boolean(const std::string& key, bool fallback);
  std::string text(const std::string& key, const std::string& fallback);
  /// A frame name: text() without a leading slash (tfFrameName(): "/robot_0/odom" is tf2's
  /// "robot_0/odom").
  std::string frame(const std::string& key, const std::string& fallback);
  /// A list of at most @p max_entries strings; empty when absent.
  /// @throws ParameterError ("~<key>", or "~<key>[i]" for an entry) when it is not a list, is
  ///         longer, or an entry is not a string
  std::vector<std::string> textList(const std::string& key, std::size_t max_entries);
  /// The keys of the map parameter @p key, sorted; none when it is absent.
  /// @throws ParameterError ("~<key>") when it is present but not a map
  std::vector<std::string> mapKeys(const std::string& key);

  /// Logs every option read, once, as "name: key = value" lines.
  void echo(const std::string& node_name) const;

 private:
  bool lookup(const std::string& key, XmlRpc::XmlRpcValue* value) const;
  void remember(const std::string& key, const std::string& value, bool defaulted);

  ros::NodeHandle nh_;
  std::vector<std::string> lines_;
};

/// Logs a scenario's loaded values once (its YAML, one line per entry) under @p node_name.
void echoScenario(const std::string& node_name, const ros::NodeHandle& private_nh,
                  const std::string& name = "scenario");

/// ~clock_skew/{policy,window,max_offset,max_drift_rate} (doc/multi_host.md), each refused by
/// its key.
StampCorrectionOptions readClockSkewOptions(NodeOptionReader& reader);

}  // namespace projection_collision_avoidance
