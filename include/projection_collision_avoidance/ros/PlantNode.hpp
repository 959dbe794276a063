#pragma once

#include <deque>
#include <mutex>
#include <random>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <geometry_msgs/AccelStamped.h>
#include <ros/ros.h>
#include <tf2_ros/transform_broadcaster.h>

#include "projection_collision_avoidance/AgentIntegrator.hpp"
#include "projection_collision_avoidance/RelativeMeasurement.h"
#include "projection_collision_avoidance/Scenario.hpp"
#include "projection_collision_avoidance/ros/InputAdmission.hpp"
#include "projection_collision_avoidance/ros/InputGuard.hpp"
#include "projection_collision_avoidance/ros/RosParameters.hpp"

namespace projection_collision_avoidance {

/// The plant node's own options (besides the scenario), read once from its private namespace.
struct PlantNodeOptions {
  double rate = 0.0;                        ///< Hz; ticks at t_k = k / rate
  std::string world_frame = "world";        ///< frame of odometry, tf parent, measurements
  std::string leader_frame = "leader";      ///< the leader's tf frame
  std::string follower_frame = "follower";  ///< the follower's tf frame
  double noise_position = 0.0;              ///< m, std dev of the measured relative position
  double noise_velocity = 0.0;              ///< m/s, std dev of the measured relative velocity
  double dropout = 0.0;                     ///< probability that a measurement is dropped
  double latency = 0.0;           ///< s; a measurement sampled at t is published at t + latency
  double outage_start = 0.0;      ///< s of simulated time at which a measurement outage begins
  double outage_duration = 0.0;   ///< s; no measurement is sampled in the outage; 0 = none
  int noise_seed = 1;             ///< seed of the noise and dropout draws
  double command_timeout = 0.5;   ///< s; an older command (by its stamp) counts as zero
  bool publish_clock = false;     ///< drive the ticks on wall time and publish /clock
  double real_time_factor = 1.0;  ///< simulated s per wall s with publish_clock
  double duration = 0.0;          ///< s of simulated time, then shut down; 0 = forever
  /// Wall s for which, with publish_clock, simulated time stays at its start until every
  /// follower subscribes its relative_measurement (a large formation loading); 0 = no wait.
  double wait_for_followers = 0.0;
  /// With publish_clock: tick k + 1 waits (wall time, at most lockstep_timeout s) until every
  /// agent that has commanded answered tick k with a command stamped t_k, and integrates
  /// [t_k, t_k+1] with those commands: the sampled loop of cf_sim, however loaded the machine.
  bool lockstep = false;
  double lockstep_timeout = 1.0;  ///< wall s a tick waits for the commands in lockstep
};

/// The simulated world: the leader and its followers, double integrators integrated exactly by
/// AgentIntegrator with the commands held between ticks and the leader's disturbance u_d applied
/// exactly, as cf_sim does. The followers are the scenario's formation (layoutFormation()): one
/// named `follower` (tf frame ~follower_frame) without a formation section, else `follower_<i>`
/// (frame of the same name), i = 1 .. N, each measured relative to its target.
///
/// Subscribes `leader/command` and `<follower>/command` (geometry_msgs/AccelStamped; each held
/// until replaced, and taken as zero once older than command_timeout; a command that is
/// non-finite, acts on an axis the model lacks, is not in the agent's frame, is stamped more
/// than command_timeout ahead of the plant's time or before the last accepted one is rejected,
/// counted and warned about once per kind). At each tick t_k = k / rate it publishes
/// `leader/odom`, `<follower>/odom` (nav_msgs/Odometry), tf world -> each agent's frame,
/// `<follower>/relative_measurement` (RelativeMeasurement of x_target - x_i with noise, dropout,
/// latency and an optional outage), at most 20 Hz (of simulated time) `agent_markers`
/// (visualization_msgs/MarkerArray: agents, names, and a line from each follower to its target)
/// and, with publish_clock, /clock = t_k; then it integrates every agent to t_{k+1} and publishes
/// the command it held over that step as `leader/applied_command` and
/// `<follower>/applied_command`.
///
/// Time: with publish_clock the plant owns simulated time (stamps t_k from 0), ticking on a wall
/// timer at rate * real_time_factor (catching up ticks that a late callback missed). Otherwise it
/// ticks on ROS time, catching up every tick that is due; scenario time is ROS time under
/// use_sim_time and the time since the first tick otherwise.
class PlantNode {
 public:
  /// @throws ParameterError naming the parameter when the scenario or an option is invalid
  PlantNode(ros::NodeHandle nh, ros::NodeHandle private_nh);

 private:
  /// One simulated vehicle and its command input.
  struct Agent {
    Agent(const std::string& agent_name, const std::string& tf_frame, const AgentModel& model,
          double step, const Eigen::VectorXd& initial_state, const SignalProfile& disturbance,
          double command_timeout);

    std::string name;   ///< topic prefix: "leader", "follower"
    std::string frame;  ///< tf frame; commands must carry it as frame_id
    AgentIntegrator<GenericDimensions> integrator;
    Eigen::VectorXd command;  ///< latest accepted command (m/s^2)
    InputGuard command_guard;
    bool command_timed_out = false;  ///< the last tick used zero for lack of a fresh command
    ros::Subscriber command_subscriber;
    ros::Publisher odom_publisher;
    ros::Publisher applied_command_publisher;  ///< the command integrated over each tick
  };

  /// A follower: its agent, its target, and its relative measurements waiting for their latency.
  struct Follower {
    Agent agent;
    int target = 0;  ///< 0: the leader; j: followers_[j - 1]
    ros::Publisher measurement_publisher;
    std::deque<RelativeMeasurement> pending;  ///< sampled, in time order, not yet published
    unsigned dropped = 0;                     ///< measurements dropped so far (not the outage)
    bool in_outage = false;                   ///< the latest tick lay in the outage
  };

  void onCommand(Agent* agent, const geometry_msgs::AccelStamped::ConstPtr& msg);
  void onWallTick(const ros::WallTimerEvent& event);
  void onRosTick(const ros::TimerEvent& event);
  /// The body of onRosTick() (mutex_ held): the ticks due at ROS time now.
  void rosTick();
  /// Samples, publishes and integrates tick k; false once the duration is reached (and then
  /// requests the shutdown).
  bool tick(long k);
  void publishMeasurement(Follower* follower, long k, const ros::Time& stamp);
  /// Publishes the command the agent's tick k at time t (s) integrates, and integrates it.
  void advanceAgent(Agent* agent, double t, const ros::Time& stamp);
  /// Integrates every agent over [t_k, t_k+1] with its command held; the leader under u_d.
  void advanceAll(long k);
  /// Lockstep: whether every agent that has commanded has a command stamped at or after t_k.
  bool commandsAnswer(long k) const;
  void publishMarkers(const ros::Time& stamp);
  /// The agent a follower is measured against.
  const Agent& targetOf(const Follower& follower) const;
  /// The held command, or zero when it is absent or older than command_timeout at @p now.
  GenericDimensions::InputVector commandAt(Agent* agent, const ros::Time& now);
  /// The stamp of tick k: origin + k / rate.
  ros::Time stampOf(long k) const;
  void stop(const std::string& why);

  ros::NodeHandle nh_;
  std::string name_;
  Scenario scenario_;
  NodeOptionReader reader_;
  PlantNodeOptions options_;
  int axes_;

  std::mutex mutex_;  ///< guards everything below against concurrent callbacks (nodelets)
  ClockWatch clock_;  ///< jumps back of ROS time (they restart the command guards' timelines)
  Agent leader_;
  std::vector<Follower> followers_;  ///< in index order; never resized after the subscriptions
  std::mt19937 rng_;
  std::normal_distribution<double> normal_{0.0, 1.0};
  std::uniform_real_distribution<double> uniform_{0.0, 1.0};
  long next_tick_ = 0;
  long last_tick_ = -1;  ///< tick at the duration; -1 = run forever
  long ticks_per_marker_ = 1;
  bool started_ = false;
  bool running_ = true;
  ros::Time origin_;                    ///< ROS time of scenario time 0
  ros::WallTime wall_origin_;           ///< wall time of tick 0 (publish_clock)
  bool waiting_for_followers_ = false;  ///< holding simulated time (~wait_for_followers)
  bool holding_ = false;                ///< lockstep: a tick waits for commands since hold_start_
  ros::WallTime hold_start_;
  std::uint64_t lockstep_timeouts_ = 0;  ///< ticks that ran without every command
  ros::WallTime rate_check_wall_;
  long rate_check_tick_ = 0;

  ros::Publisher clock_publisher_;
  ros::Publisher marker_publisher_;
  tf2_ros::TransformBroadcaster tf_broadcaster_;
  ros::WallTimer wall_timer_;
  ros::Timer timer_;
  ros::WallTimer shutdown_timer_;
};

}  // namespace projection_collision_avoidance
