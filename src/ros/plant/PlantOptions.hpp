#pragma once

#include <limits>
#include <map>
#include <string>
#include <vector>

#include "projection_collision_avoidance/ros/RosParameters.hpp"
#include "projection_collision_avoidance/sim/MeasurementChannel.hpp"
#include "projection_collision_avoidance/sim/Scenario.hpp"

namespace projection_collision_avoidance {

/// How the plant simulates an agent (~vehicles/<agent>/kind).
enum class VehicleKind {
  kDoubleIntegrator,  ///< "double_integrator": AccelStamped on <agent>/command (the default)
  kVelocity,          ///< "velocity": VelocityLagVehicle, Twist on <agent>/cmd_vel
  kUnicycle,          ///< "unicycle": UnicycleVehicle, Twist on <agent>/cmd_vel
};

/// "double_integrator", "velocity", "unicycle".
const char* toString(VehicleKind kind);

/// One agent's entry of ~vehicles (doc/ros_interface.md).
struct VehicleOptions {
  VehicleKind kind = VehicleKind::kDoubleIntegrator;
  std::string key;            ///< "~vehicles/<agent>": its parameters' prefix in errors
  double velocity_lag = 0.0;  ///< τ (s) of the velocity (and the unicycle's yaw rate)
  double max_speed = std::numeric_limits<double>::infinity();     ///< m/s; inf: none
  double max_yaw_rate = std::numeric_limits<double>::infinity();  ///< rad/s (unicycle); inf: none
  double heading = 0.0;       ///< rad: the unicycle's initial θ, the velocity kind's fixed yaw
  bool twist_in_body = true;  ///< velocity: cmd_vel's linear part in the body frame, else world
  /// "": odometry in the world frame; else the frame of the vehicle's own odometry, which
  /// starts at its initial pose as a real base's does (world -> odom_frame broadcast as static)
  std::string odom_frame;
};

/// The plant node's own options (besides the scenario), read once from its private namespace.
struct PlantNodeOptions {
  double rate = 0.0;                        ///< Hz; ticks at t_k = k / rate
  std::string world_frame = "world";        ///< frame of odometry, tf parent, measurements
  std::string leader_frame = "leader";      ///< the leader's tf frame
  std::string follower_frame = "follower";  ///< the follower's tf frame
  MeasurementFaults faults;                 ///< ~measurement_*, ~noise_seed
  double command_timeout = 0.5;             ///< s; an older command (by its stamp) counts as zero
  /// ~clock_skew/...: how the commands' stamps are put on the plant's clock (a follower on
  /// another host whose clock differs; doc/multi_host.md)
  StampCorrectionOptions clock_skew;
  bool publish_clock = false;     ///< drive the ticks on wall time and publish /clock
  double real_time_factor = 1.0;  ///< simulated s per wall s with publish_clock
  double duration = 0.0;          ///< s of simulated time, then shut down; 0 = forever
  /// Wall s for which, with publish_clock, simulated time stays at its start until every
  /// follower subscribes its relative_measurement (a large formation loading); 0 = no wait.
  double wait_for_followers = 0.0;
  /// Topics (resolved in the plant's namespace) that, with wait_for_followers, must each have a
  /// subscriber at the master too before simulated time starts: a test's observers, say.
  std::vector<std::string> wait_for_subscribers;
  /// With publish_clock: tick k + 1 waits (wall time, at most lockstep_timeout s) until every
  /// agent that has commanded answered tick k with a command stamped t_k, and integrates
  /// [t_k, t_k+1] with those commands: the sampled loop of cf_sim, however loaded the machine.
  bool lockstep = false;
  double lockstep_timeout = 1.0;  ///< wall s a tick waits for the commands in lockstep
  /// ~vehicles by agent name ("leader", "follower", "follower_<i>"); an agent not listed is a
  /// double integrator.
  std::map<std::string, VehicleOptions> vehicles;
};

/// The plant node's options from its private namespace, each validated (the message names the
/// key).
PlantNodeOptions readPlantOptions(NodeOptionReader& reader, const Scenario& scenario);

}  // namespace projection_collision_avoidance
