#pragma once

/// @file
/// YAML text to a yaml-cpp tree through libyaml's event parser (internal to the configuration
/// library). yaml-cpp's own scanner costs over a thousand instructions per byte, most of cf_sim's
/// start-up; libyaml parses the same text in a small fraction of that. The tree is the one
/// YAML::Load() builds: plain scalars tagged "?", quoted and block scalars "!", explicit tags
/// resolved ("!!str" is tag:yaml.org,2002:str), an untagged plain "", "~", "null", "Null" or
/// "NULL" a null node, aliases sharing their anchor's node.
///
/// The limits of ConfigurationLoader.hpp (kMaxScenarioBytes, kMaxScenarioDepth, kMaxScenarioNodes)
/// are checked while the file is read and the events arrive, so that a refused text costs no
/// more than the limits.

#include <cstddef>
#include <functional>
#include <string>

#include <yaml-cpp/yaml.h>

namespace projection_collision_avoidance::detail {

/// Events read between two calls of the cancellation predicate.
constexpr std::size_t kCancelPollEvents = 256;

/// The first document of @p text as a yaml-cpp tree (a null node if there is none).
/// @param cancelled when given, called before the first event and every kCancelPollEvents
///        events; once it returns true the parse ends with ScenarioLoadCancelled
/// @throws ParameterError with key "(file)" for text that is not valid YAML (with its line and
///         column), an alias to an unknown anchor or inside the collection it names, a key that
///         appears twice in one map, or text beyond a limit (naming the limit and where)
/// @throws ScenarioLoadCancelled when @p cancelled returned true
YAML::Node parseYaml(const std::string& text, const std::function<bool()>& cancelled = {});

/// The text of the file at @p path, at most kMaxScenarioBytes: a regular file is refused by its
/// size before it is read, any other (a pipe, a device) once one byte more has been read.
/// @throws ParameterError with key "(file)" for a directory, a file that cannot be read, or one
///         over the size limit (naming the path, its size and the limit)
std::string readYamlFile(const std::string& path);

}  // namespace projection_collision_avoidance::detail
