#pragma once

#include <string>
#include <vector>

#include "projection_collision_avoidance/sim/SignalProfile.hpp"
#include "projection_collision_avoidance/sim/WorldSpec.hpp"

#include "YamlReader.hpp"

namespace projection_collision_avoidance::detail {

/// The pulses of the list @p name ({start, end, vector}); each is checked against @p size
/// entries, so that an error names the entry by its path in the file
/// ("leader.disturbance.0.vector").
std::vector<Pulse> readPulses(YamlReader& parent, const std::string& name, Eigen::Index size);

/// The sinusoids of the list @p name ({amplitude, frequency, phase (0)}).
std::vector<Sinusoid> readSinusoids(YamlReader& parent, const std::string& name);

/// Section `world` (WorldSpec), read key by key; an unconfigured world when it is absent. The
/// values' ranges are checked by WorldSpec::validate().
WorldSpec readWorld(YamlReader& reader, Eigen::Index state_size);

}  // namespace projection_collision_avoidance::detail
