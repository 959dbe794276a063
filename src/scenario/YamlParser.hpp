#pragma once

/// @file
/// YAML text to a yaml-cpp tree through libyaml's event parser (internal to the scenario
/// library). yaml-cpp's own scanner costs over a thousand instructions per byte, most of cf_sim's
/// start-up; libyaml parses the same text in a small fraction of that. The tree is the one
/// YAML::Load() builds: plain scalars tagged "?", quoted and block scalars "!", explicit tags
/// resolved ("!!str" is tag:yaml.org,2002:str), an untagged plain "", "~", "null", "Null" or
/// "NULL" a null node, aliases sharing their anchor's node.

#include <string>

#include <yaml-cpp/yaml.h>

namespace projection_collision_avoidance::detail {

/// The first document of @p text as a yaml-cpp tree (a null node if there is none).
/// @throws ParameterError with key "(file)" for text that is not valid YAML (with its line and
///         column), an alias to an unknown anchor, or a key that appears twice in one map
YAML::Node parseYaml(const std::string& text);

}  // namespace projection_collision_avoidance::detail
