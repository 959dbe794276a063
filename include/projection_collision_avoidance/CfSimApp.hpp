#pragma once

#include <ostream>
#include <string>
#include <vector>

namespace projection_collision_avoidance {

/// The cf_sim command: `SCENARIO.yaml [--set key=value]... [--csv FILE]`. Loads the scenario,
/// runs simulate(), writes the CSV if asked and prints the summary line
/// `max_xi=.. max_xi_hat=.. xi_max=.. min_separation=.. time_outside=.. wall_s=..` to @p out.
/// @return 0 on success, 1 for an invalid scenario (the message names the key), 2 for a usage
///         error, 3 when the CSV cannot be written
int runCfSim(const std::vector<std::string>& arguments, std::ostream& out, std::ostream& err);

}  // namespace projection_collision_avoidance
