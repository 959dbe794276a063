#pragma once

/// @file
/// The sections of a scenario file that a follower's configuration and a whole scenario share,
/// and the steps around reading a tree (internal to the configuration library; the scenario
/// library reads the rest of the file with them).

#include <initializer_list>
#include <string>
#include <utility>
#include <vector>

#include <yaml-cpp/yaml.h>

#include "projection_collision_avoidance/core/AgentModel.hpp"
#include "projection_collision_avoidance/core/Formation.hpp"
#include "projection_collision_avoidance/core/ParameterError.hpp"

#include "YamlReader.hpp"

namespace projection_collision_avoidance::detail {

/// Applies each override "dotted.path=value" to @p root, in order: the value is read as YAML
/// (so "[1, 2]" is a list) and replaces or adds the entry at that path, a numeric path element
/// indexing a list. Throws ParameterError naming the override's key.
void applyOverrides(YAML::Node& root, const std::vector<std::string>& overrides);

/// The `model` section (double_integrator or linear), checked by validateAgentModel().
AgentModel readModel(YamlReader& reader);

/// Each number of @p keys that @p section has, into its place; the absent ones keep theirs.
void readNumbers(YamlReader& section, std::initializer_list<std::pair<const char*, double*>> keys);

/// The `formation` section when present (configured), else one follower ("follower"); each
/// key's own checks only (FormationSpec::validate() checks it against the model).
FormationSpec readFormation(YamlReader& reader);

/// @p read applied to @p root after @p overrides: a root that is not a map is refused, and an
/// error of yaml-cpp's that no read named becomes a ParameterError of "(root)".
template <typename Read>
auto readRoot(YAML::Node root, const std::vector<std::string>& overrides, const Read& read)
    -> decltype(read(root)) {
  if (!root.IsMap()) {
    throw ParameterError("(root)", "a scenario is a YAML map");
  }
  try {
    applyOverrides(root, overrides);
    return read(root);
  } catch (const YAML::Exception& error) {  // every read names its key; this is a safety net
    throw ParameterError("(root)", std::string("cannot be read: ") + error.what());
  }
}

}  // namespace projection_collision_avoidance::detail
