#pragma once

#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <geometry_msgs/AccelStamped.h>
#include <ros/callback_queue.h>
#include <ros/ros.h>
#include <tf2_ros/static_transform_broadcaster.h>
#include <tf2_ros/transform_broadcaster.h>

#include "projection_collision_avoidance/NeighbourArray.h"
#include "projection_collision_avoidance/RelativeMeasurement.h"
#include "projection_collision_avoidance/cycle/InputGuard.hpp"
#include "projection_collision_avoidance/cycle/InputTimeline.hpp"
#include "projection_collision_avoidance/ros/CountedPublisher.hpp"
#include "projection_collision_avoidance/ros/InputAdmission.hpp"
#include "projection_collision_avoidance/ros/RosParameters.hpp"
#include "projection_collision_avoidance/sim/AgentIntegrator.hpp"
#include "projection_collision_avoidance/sim/FollowerWorld.hpp"
#include "projection_collision_avoidance/sim/MeasurementChannel.hpp"
#include "projection_collision_avoidance/sim/Scenario.hpp"

#include "plant/PlantClock.hpp"
#include "plant/PlantOptions.hpp"
#include "plant/PlantVehicles.hpp"

namespace projection_collision_avoidance {

/// The simulated world: the leader and its followers, double integrators integrated exactly by
/// AgentIntegrator with the commands held between ticks and the leader's disturbance u_d applied
/// exactly, as cf_sim does. The followers are the scenario's formation (layoutFormation()): one
/// named `follower` (tf frame ~follower_frame) without a formation section, else `follower_<i>`
/// (frame of the same name), i = 1 .. N, each measured relative to its target.
///
/// Subscribes `leader/command` and `<follower>/command` (geometry_msgs/AccelStamped; each held
/// until replaced, and taken as zero once older than command_timeout; a command that is
/// non-finite, acts on an axis the model lacks, is in neither the agent's frame nor the world
/// frame, is stamped more
/// than command_timeout ahead of the plant's time or before the last accepted one is rejected,
/// counted and warned about once per kind). At each tick t_k = k / rate it publishes
/// `leader/odom`, `<follower>/odom` (nav_msgs/Odometry), tf world -> each agent's frame,
/// `<follower>/relative_measurement` (RelativeMeasurement of x_target - x_i with noise, dropout,
/// latency and an optional outage), at most 20 Hz (of simulated time) `agent_markers`
/// (visualization_msgs/MarkerArray: agents, names, and a line from each follower to its target)
/// and, with publish_clock, /clock = t_k; then it integrates every agent to t_{k+1} and publishes
/// the command it held over that step as `leader/applied_command` and
/// `<follower>/applied_command`. With ~lockstep tick k + 1 does that integration instead, once
/// the commands answering sample k are in (PlantClock holds simulated time until then), so
/// that every agent integrates [t_k, t_k+1] with its answer to t_k, as cf_sim does.
///
/// The scenario's `world` acts as in cf_sim (FollowerWorld): follower i integrates its
/// disturbance w_i(t) (pulses, sinusoids, gusts drawn up to the longer of the scenario's duration
/// and ~duration), each tick's held command goes through its true vehicle before it is integrated
/// (and is published as applied_command so), and the world's noise of tick k is added to the
/// relative state sampled at tick k. With formation.neighbours, each tick first publishes
/// `<follower>/neighbours` (NeighbourArray: every other agent within formation.neighbours.radius,
/// x_j - x_i exact, stamped and framed as that tick's relative_measurement).
///
/// An agent listed in ~vehicles with kind `velocity` or `unicycle` is a PlantVehicle instead: it
/// takes Twists on `<agent>/cmd_vel` (and TwistStamped on `<agent>/cmd_vel_stamped`), publishes
/// its odometry and tf with its heading and twist in its body frame, and its applied command as
/// a TwistStamped; its measurements are those of its odometry's origin, as for a double
/// integrator; the leader's u_d does not act on it. Lockstep waits for a vehicle's Twist
/// received after sample k went out.
///
/// Time: PlantClock. With publish_clock the plant owns simulated time (stamps t_k from 0), ticking
/// on a wall timer at rate * real_time_factor (catching up ticks that a late callback missed; in
/// lockstep at most at real time until every agent with a sender has commanded).
/// Otherwise it ticks on ROS time, catching up every tick that is due; scenario time is ROS time
/// under use_sim_time and the time since the first tick otherwise.
class PlantWorld {
 public:
  /// @throws ParameterError naming the parameter when the scenario or an option is invalid
  PlantWorld(ros::NodeHandle nh, ros::NodeHandle private_nh);

 private:
  /// One simulated vehicle and its command input.
  struct Agent {
    Agent(const std::string& agent_name, const std::string& tf_frame, const AgentModel& model,
          double step, const Eigen::VectorXd& initial_state, const SignalProfile& disturbance,
          double command_timeout, const StampCorrectionOptions& clock_skew);

    std::string name;   ///< topic prefix: "leader", "follower"
    std::string frame;  ///< tf frame; commands carry it or the world frame as frame_id
    AgentIntegrator<GenericDimensions> integrator;
    Eigen::VectorXd command;  ///< latest accepted command (m/s^2)
    /// The commands' timeline: judged on the sender's clock, their stamps put on the plant's
    /// (never before the one before: stamp()); restarted by the plant clock's jump hook.
    InputTimeline command_timeline;
    bool command_timed_out = false;  ///< the last tick used zero for lack of a fresh command
    ros::Subscriber command_subscriber;
    CountedPublisher odom_publisher;
    CountedPublisher applied_command_publisher;  ///< the command integrated over each tick
    std::unique_ptr<PlantVehicle> vehicle;       ///< a vehicle kind; null: the double integrator
    /// Lockstep with a vehicle: the controller's output (agent/command, which an adapter turns
    /// into cmd_vel) is watched too, so that a vehicle answers a tick once its controller has:
    /// the latest stamp seen there (ns; -1: none yet).
    std::int64_t controller_stamp = -1;
    ros::Subscriber controller_subscriber;

    /// [p; v] of the agent (2 axes entries).
    Eigen::VectorXd state() const {
      return vehicle ? vehicle->state() : Eigen::VectorXd(integrator.state());
    }
  };

  /// A follower's `neighbours` output, allocated once: each tick moves the entries of the agents
  /// within the radius into the message and, the tick after, back.
  struct NeighbourOutput {
    CountedPublisher publisher;
    NeighbourArray message;          ///< header set once but its stamp; entries moved in
    std::vector<Neighbour> entries;  ///< one per other agent: its id, k entries each
    std::vector<int> agents;         ///< each entry's agent: 0 the leader, j follower j
    std::vector<std::size_t> taken;  ///< the entry each of message.neighbours came from
  };

  /// A follower: its agent, its target, its measurement topic, its part of the world.
  struct Follower {
    Agent agent;
    int target = 0;  ///< 0: the leader; j: followers_[j - 1]
    CountedPublisher measurement_publisher;
    FollowerWorld world;         ///< the scenario's world for it (nothing without a world section)
    NeighbourOutput neighbours;  ///< with formation.neighbours
  };

  /// ~wait_for_subscribers: how many of its topics have a subscriber at the master (queried at
  /// most every 50 wall ms; the last answer between).
  int subscribedWaitedTopics();
  /// Makes @p agent the vehicle ~vehicles asks for, if any (from its initial state).
  void attachVehicle(Agent* agent);
  /// Advertises the agent's outputs and subscribes its command input.
  void connectAgent(Agent* agent);
  /// The plant's time: the last tick's stamp, or ROS time before the clock runs.
  ros::Time plantNow() const { return clock_ ? clock_->now() : ros::Time::now(); }
  using CommandEvent = ros::MessageEvent<geometry_msgs::AccelStamped const>;
  void onCommand(Agent* agent, const CommandEvent& event);
  /// Publishes the agent's odometry at @p stamp and appends its transform.
  void sampleAgent(Agent* agent, const ros::Time& stamp,
                   std::vector<geometry_msgs::TransformStamped>* transforms);
  /// Samples, publishes and integrates tick k (mutex_ held); false once the duration is
  /// reached (and then requests the shutdown).
  bool tick(long k);
  /// Samples follower @p index's channel at tick k and publishes what is due.
  void publishMeasurement(int index, long k);
  /// Sets up follower @p index's `neighbours` output (formation.neighbours).
  void advertiseNeighbours(int index);
  /// Publishes follower @p index's sensed agents at @p stamp (states_ filled this tick).
  void publishNeighbours(int index, const ros::Time& stamp);
  /// Publishes the command the agent's tick k at time t (s) integrates, and integrates it; a
  /// follower's through its true vehicle (@p world; null for the leader).
  void advanceAgent(Agent* agent, double t, const ros::Time& stamp, FollowerWorld* world = nullptr);
  /// Integrates every agent over [t_k, t_k+1] with its command held; the leader under u_d.
  void advanceAll(long k);
  /// Lockstep: whether every agent that has commanded and still has a sender answered sample k:
  /// a command stamped at or after t_k (a vehicle: a Twist received after sample k went out).
  bool commandsAnswer(long k) const;
  /// Lockstep: whether every agent with a sender on its command topic has commanded.
  bool everyAgentCommanded() const;
  /// A subscriber of @p agent's command topic (`<agent>/command`), on the tick thread's queue
  /// when the plant ticks on a thread of its own.
  ros::Subscriber subscribeCommand(Agent* agent,
                                   const boost::function<void(const CommandEvent&)>& callback);
  void publishMarkers(const ros::Time& stamp);
  /// The agent a follower is measured against.
  const Agent& targetOf(const Follower& follower) const;
  /// The held command, or zero when it is absent or older than command_timeout at @p now.
  GenericDimensions::InputVector commandAt(Agent* agent, const ros::Time& now);
  void stop(const std::string& why);

  ros::NodeHandle nh_;
  std::string name_;
  Scenario scenario_;
  NodeOptionReader reader_;
  PlantNodeOptions options_;
  int axes_;

  /// On wall time, the commands' callbacks: the tick thread calls them before each tick, so that
  /// a command wakes no thread (a follower in the same process publishes it and goes on).
  ros::CallbackQueue command_queue_;
  std::mutex mutex_;  ///< guards everything below against concurrent callbacks (nodelets)
  Agent leader_;
  std::vector<Follower> followers_;  ///< in index order; never resized after the subscriptions
  std::unique_ptr<MeasurementChannels> channels_;
  /// With formation.neighbours: every agent's state this tick (0 the leader, j follower j).
  std::vector<Eigen::VectorXd> states_;
  long ticks_per_marker_ = 1;
  long last_tick_ = -1;  ///< tick at the duration; -1 = run forever

  ros::Publisher clock_publisher_;
  ros::Publisher marker_publisher_;
  tf2_ros::TransformBroadcaster tf_broadcaster_;
  tf2_ros::StaticTransformBroadcaster static_broadcaster_;  ///< world -> the vehicles' odom frames
  ros::WallTimer shutdown_timer_;
  std::vector<std::string> waited_topics_;  ///< ~wait_for_subscribers, resolved
  ros::WallTime topics_polled_;             ///< when the master was last asked
  int subscribed_topics_ = 0;               ///< its answer then
  std::unique_ptr<PlantClock> clock_;       ///< started last
};

}  // namespace projection_collision_avoidance
