#pragma once

/// @file
/// Reads the YAML scenario format of README.md, "Scenario files" (yaml-cpp). Every error is a
/// ParameterError whose key is the dotted path of the offending entry.

#include <string>
#include <vector>

#include <yaml-cpp/yaml.h>

#include "projection_collision_avoidance/Scenario.hpp"

namespace projection_collision_avoidance {

/// Loads a scenario file and applies overrides "dotted.path=value" in order; each value is read
/// as YAML (so "[1, 2]" is a list) and replaces or adds the entry at that path, a numeric path
/// element indexing a list. Unknown keys are refused.
/// @throws ParameterError for a missing file, a syntax error, an unknown or missing key, a value
///         of the wrong type or size, or a parameter the controller design refuses
Scenario loadScenarioFile(const std::string& path, const std::vector<std::string>& overrides = {});

/// As loadScenarioFile(), from a YAML tree (for example one converted from ROS parameters).
Scenario scenarioFromYaml(const YAML::Node& root, const std::vector<std::string>& overrides = {});

/// As loadScenarioFile(), from YAML text.
Scenario parseScenario(const std::string& yaml_text,
                       const std::vector<std::string>& overrides = {});

}  // namespace projection_collision_avoidance
