#pragma once

#include <string>

#include "projection_collision_avoidance/ros/RosParameters.hpp"
#include "projection_collision_avoidance/sim/MeasurementChannel.hpp"
#include "projection_collision_avoidance/sim/Scenario.hpp"

namespace projection_collision_avoidance {

/// The plant node's own options (besides the scenario), read once from its private namespace.
struct PlantNodeOptions {
  double rate = 0.0;                        ///< Hz; ticks at t_k = k / rate
  std::string world_frame = "world";        ///< frame of odometry, tf parent, measurements
  std::string leader_frame = "leader";      ///< the leader's tf frame
  std::string follower_frame = "follower";  ///< the follower's tf frame
  MeasurementFaults faults;                 ///< ~measurement_*, ~noise_seed
  double command_timeout = 0.5;             ///< s; an older command (by its stamp) counts as zero
  bool publish_clock = false;               ///< drive the ticks on wall time and publish /clock
  double real_time_factor = 1.0;            ///< simulated s per wall s with publish_clock
  double duration = 0.0;                    ///< s of simulated time, then shut down; 0 = forever
  /// Wall s for which, with publish_clock, simulated time stays at its start until every
  /// follower subscribes its relative_measurement (a large formation loading); 0 = no wait.
  double wait_for_followers = 0.0;
  /// With publish_clock: tick k + 1 waits (wall time, at most lockstep_timeout s) until every
  /// agent that has commanded answered tick k with a command stamped t_k, and integrates
  /// [t_k, t_k+1] with those commands: the sampled loop of cf_sim, however loaded the machine.
  bool lockstep = false;
  double lockstep_timeout = 1.0;  ///< wall s a tick waits for the commands in lockstep
};

/// The plant node's options from its private namespace, each validated (the message names the
/// key).
PlantNodeOptions readPlantOptions(NodeOptionReader& reader, const Scenario& scenario);

}  // namespace projection_collision_avoidance
