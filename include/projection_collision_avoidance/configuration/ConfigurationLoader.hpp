#pragma once

/// @file
/// Reads a follower's configuration from the YAML scenario format of doc/cf_sim.md, "Scenario
/// files": the `model`, `controller` and `formation` sections, into a FollowerConfiguration. The
/// simulation's sections (`leader`, `follower`, `simulation` and the modelled link
/// `controller.leader_information.link`) may be present and are not read here: the scenario
/// library (scenario/ScenarioLoader.hpp) reads the whole file for the simulators. Needs the core
/// and the YAML libraries only. Every error is a ParameterError whose key is the dotted path of
/// the offending entry.

#include <cstddef>
#include <functional>
#include <stdexcept>
#include <string>
#include <vector>

#include <yaml-cpp/yaml.h>

#include "projection_collision_avoidance/core/FollowerConfiguration.hpp"

namespace projection_collision_avoidance {

// Limits on a scenario's YAML, checked while it is read (doc/cf_sim.md, "Limits"). The largest
// scenario of config/scenarios has under 2 KB, about 100 nodes, and lists and maps nested 6
// deep; a formation of any size is one number (formation.followers).

/// Bytes of a scenario file (or text): 1 MiB.
constexpr std::size_t kMaxScenarioBytes = std::size_t{1} << 20U;
/// Lists and maps nested in one another, the root counting as 1.
constexpr std::size_t kMaxScenarioDepth = 64;
/// Nodes of the tree (scalars, lists, maps, keys included), an alias counting as every node it
/// repeats: at most about 55 MB of yaml-cpp tree.
constexpr std::size_t kMaxScenarioNodes = 100000;

/// A load ended by its cancellation predicate (the `cancelled` of the load's options).
class ScenarioLoadCancelled : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// What a caller adds to a load of a follower configuration.
struct ConfigurationLoadOptions {
  /// Polled while the YAML is parsed (before the first event and then every few hundred); once
  /// it returns true, the load ends with ScenarioLoadCancelled. Empty: never cancelled.
  std::function<bool()> cancelled;
  /// The caller's own checks of the values read, run after the per-key checks and before the
  /// controller design's derived checks (Hurwitz gains, RK4 stability, ...), so that a value the
  /// caller refuses is named rather than a key the design derives from it. Throws
  /// ParameterError with a dotted key. Empty: none.
  std::function<void(const FollowerConfiguration&)> check;
};

/// Loads the follower's configuration from a scenario file, after the overrides
/// "dotted.path=value" (as loadScenarioFile()). Unknown keys are refused, in the sections read.
/// @throws ParameterError for a missing file, a syntax error, a limit exceeded, an unknown or
///         missing key, a value of the wrong type or size, or a parameter the controller design
///         refuses
/// @throws ScenarioLoadCancelled when @p options cancelled the load
FollowerConfiguration loadFollowerConfigurationFile(const std::string& path,
                                                    const std::vector<std::string>& overrides = {},
                                                    const ConfigurationLoadOptions& options = {});

/// As loadFollowerConfigurationFile(), from a YAML tree (for example one converted from ROS
/// parameters).
FollowerConfiguration followerConfigurationFromYaml(const YAML::Node& root,
                                                    const std::vector<std::string>& overrides = {},
                                                    const ConfigurationLoadOptions& options = {});

/// As loadFollowerConfigurationFile(), from YAML text (at most kMaxScenarioBytes).
FollowerConfiguration parseFollowerConfiguration(const std::string& yaml_text,
                                                 const std::vector<std::string>& overrides = {},
                                                 const ConfigurationLoadOptions& options = {});

}  // namespace projection_collision_avoidance
