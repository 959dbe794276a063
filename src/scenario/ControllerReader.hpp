#pragma once

/// @file
/// Reads the `controller` section of a scenario (internal to the scenario library).

#include "projection_collision_avoidance/core/AgentModel.hpp"
#include "projection_collision_avoidance/core/ControllerParameters.hpp"
#include "projection_collision_avoidance/sim/SharedLink.hpp"

#include "YamlReader.hpp"

namespace projection_collision_avoidance::detail {

/// The controller parameters of the scenario read by @p reader, with each key's own checks (type,
/// size, range); the design's derived checks come later. The link of the shared information
/// (controller.leader_information.link) goes to @p link. Throws ParameterError naming the key.
ControllerParameters readController(YamlReader& reader, const AgentModel& model, LinkSpec* link);

}  // namespace projection_collision_avoidance::detail
