#pragma once

#include <string>

#include "projection_collision_avoidance/FollowerStatus.h"
#include "projection_collision_avoidance/core/Formation.hpp"
#include "projection_collision_avoidance/cycle/FollowerCycle.hpp"

#include "follower/FollowerInputs.hpp"

namespace projection_collision_avoidance {

/// The FollowerStatus message of one control step: the one mapping from the core's status and
/// the cycle's counters to the message (msg/FollowerStatus.msg documents each field).
/// @param frame the follower's frame (header.frame_id)
FollowerStatus toStatusMsg(const FollowerCycleOutput& out, const FollowerInputStats& inputs,
                           const FormationMember& member, const std::string& frame);

}  // namespace projection_collision_avoidance
