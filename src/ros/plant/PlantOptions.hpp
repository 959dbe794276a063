#pragma once

#include <string>

#include "projection_collision_avoidance/Scenario.hpp"
#include "projection_collision_avoidance/ros/RosParameters.hpp"
#include "projection_collision_avoidance/sim/MeasurementChannel.hpp"

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
};

/// The plant node's options from its private namespace, each validated (the message names the
/// key).
PlantNodeOptions readPlantOptions(NodeOptionReader& reader, const Scenario& scenario);

}  // namespace projection_collision_avoidance
