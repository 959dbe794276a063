#pragma once

/// @file
/// Reads the `controller` section of a scenario (internal to the configuration library).

#include <functional>

#include "projection_collision_avoidance/core/AgentModel.hpp"
#include "projection_collision_avoidance/core/ControllerParameters.hpp"

#include "YamlReader.hpp"

namespace projection_collision_avoidance::detail {

/// Reads controller.leader_information.link, the modelled link of the shared information (a
/// simulation's, read by the scenario library), from the leader_information section it is given.
using LinkSectionReader = std::function<void(YamlReader& leader_information)>;

/// The controller parameters of the scenario read by @p reader, with each key's own checks (type,
/// size, range); the design's derived checks come later. The link section, when present, goes to
/// @p read_link; without one it is skipped. Throws ParameterError naming the key.
ControllerParameters readController(YamlReader& reader, const AgentModel& model,
                                    const LinkSectionReader& read_link = {});

}  // namespace projection_collision_avoidance::detail
