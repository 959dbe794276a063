#pragma once

/// @file
/// Reads the YAML scenario format of doc/cf_sim.md, "Scenario files" (yaml-cpp): every section,
/// the simulation's with the follower's (configuration/ConfigurationLoader.hpp reads the
/// follower's alone). Every error is a ParameterError whose key is the dotted path of the
/// offending entry. The limits (kMaxScenarioBytes, ...) and ScenarioLoadCancelled are those of
/// ConfigurationLoader.hpp.

#include <functional>
#include <string>
#include <vector>

#include <yaml-cpp/yaml.h>

#include "projection_collision_avoidance/configuration/ConfigurationLoader.hpp"
#include "projection_collision_avoidance/sim/Scenario.hpp"

namespace projection_collision_avoidance {

/// What a caller adds to a load of a scenario.
struct ScenarioLoadOptions {
  /// Polled while the YAML is parsed (before the first event and then every few hundred); once
  /// it returns true, the load ends with ScenarioLoadCancelled. Empty: never cancelled.
  std::function<bool()> cancelled;
  /// The caller's own checks of the values read, run after the loader's per-key checks and
  /// before the controller design's derived checks (Hurwitz gains, RK4 stability, ...), so that
  /// a value the caller refuses is named rather than a key the design derives from it. Throws
  /// ParameterError with a dotted key. Empty: none.
  std::function<void(const Scenario&)> check;
};

/// Loads a scenario file and applies overrides "dotted.path=value" in order; each value is read
/// as YAML (so "[1, 2]" is a list) and replaces or adds the entry at that path, a numeric path
/// element indexing a list. Unknown keys are refused. A file over kMaxScenarioBytes is refused
/// by its size before it is read (any other file once that many bytes have been read).
/// @throws ParameterError for a missing file, a syntax error, a limit exceeded, an unknown or
///         missing key, a value of the wrong type or size, or a parameter the controller design
///         refuses
/// @throws ScenarioLoadCancelled when @p options cancelled the load
Scenario loadScenarioFile(const std::string& path, const std::vector<std::string>& overrides = {},
                          const ScenarioLoadOptions& options = {});

/// As loadScenarioFile(), from a YAML tree (for example one converted from ROS parameters).
Scenario scenarioFromYaml(const YAML::Node& root, const std::vector<std::string>& overrides = {},
                          const ScenarioLoadOptions& options = {});

/// As loadScenarioFile(), from YAML text (at most kMaxScenarioBytes).
Scenario parseScenario(const std::string& yaml_text, const std::vector<std::string>& overrides = {},
                       const ScenarioLoadOptions& options = {});

}  // namespace projection_collision_avoidance
