#pragma once

#include <string>

#include "projection_collision_avoidance/core/ControllerParameters.hpp"
#include "projection_collision_avoidance/core/Formation.hpp"

namespace projection_collision_avoidance {

/// What a follower is configured with, apart from any simulation: the controller of the
/// formation (the `controller` section of a scenario file, d the pair's separation) and the
/// formation it belongs to (the `formation` section), from which its own slot follows. A
/// scenario (sim/Scenario.hpp) adds what only a simulation has: the leader's input and
/// disturbance, initial states, the duration and the modelled link.
struct FollowerConfiguration {
  ControllerParameters controller;
  FormationSpec formation;

  /// Follower @p index of the formation (formationSlot()): its name, target and slot d_i.
  /// @throws ParameterError naming @p index_key when @p index is not in 1 .. formation.followers
  FormationMember member(int index, const std::string& index_key) const;
};

}  // namespace projection_collision_avoidance
