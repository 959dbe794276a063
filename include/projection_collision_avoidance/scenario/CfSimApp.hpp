#pragma once

#include <ostream>
#include <string>
#include <vector>

namespace projection_collision_avoidance {

/// The cf_sim command.
///
/// `SCENARIO.yaml [--set key=value]... [--csv FILE]` loads the scenario, runs its closed loop
/// (simulateFormation()), writes the CSV if asked and prints the summary line
/// `max_xi=.. max_xi_hat=.. xi_max=.. min_separation=.. time_outside=.. wall_s=..` to @p out. A
/// scenario with a formation section prints that line once per follower, prefixed with
/// `follower_<i> target=<name>`, then `formation followers=.. topology=.. shape=..
/// min_pair_separation=.. wall_s=..`; its CSV is one file per follower, FILE with `_follower_<i>`
/// before the extension.
///
/// `... --continuous STEP` runs the pair's continuous-time loop instead (simulateContinuous(), RK4
/// at STEP s; the sampled controller is not involved); the CSV then has one row per step.
///
/// `... --sweep FILE [--directions N] [--max-size S] [--size-step S] [--tolerance S]` runs
/// sweepDisturbance() on the scenario and writes one CSV row per configuration and direction:
/// `tracker,sharing,direction_deg,bound_limit,bound_capped,perimeter_limit,perimeter_capped`.
/// @return 0 on success, 1 for an invalid scenario or sweep option (the message names the key),
///         2 for a usage error, 3 when an output file cannot be written
int runCfSim(const std::vector<std::string>& arguments, std::ostream& out, std::ostream& err);

}  // namespace projection_collision_avoidance
