#pragma once

#include <mutex>
#include <string>

#include <Eigen/Core>
#include <nav_msgs/Odometry.h>
#include <ros/ros.h>

#include "projection_collision_avoidance/cycle/InputGuard.hpp"
#include "projection_collision_avoidance/cycle/InputTimeline.hpp"
#include "projection_collision_avoidance/cycle/TimeJumpWatch.hpp"
#include "projection_collision_avoidance/ros/CountedPublisher.hpp"
#include "projection_collision_avoidance/ros/InputAdmission.hpp"
#include "projection_collision_avoidance/sim/Scenario.hpp"

namespace projection_collision_avoidance {

/// The leader node's own options (besides the scenario), read once from its private namespace.
struct LeaderNodeOptions {
  double rate = 0.0;                    ///< Hz
  std::string leader_frame = "leader";  ///< frame_id of the command
  bool share_disturbance = true;        ///< put u_d(t) in the broadcast (empty otherwise)
  double max_future_stamp = 0.25;       ///< s an odometry stamp may lie ahead of the clock
};

/// The leader: plays the scenario's input profile u_1(t) and tells its followers about itself.
///
/// Every 1 / rate s of ROS time it publishes `leader/command` (geometry_msgs/AccelStamped, u_1
/// sampled at the tick, stamped with the tick) and, once a `leader/odom` (nav_msgs/Odometry)
/// has arrived, `leader/broadcast` (LeaderBroadcast: position and velocity of the latest odom,
/// u_1(t), and u_d(t) when shared, under the odom's header; one per odom, as a follower refuses
/// a repeated stamp). Scenario time t is ROS time under
/// use_sim_time (the plant's /clock starts at 0) and the time since the first tick otherwise.
class LeaderNode {
 public:
  /// @throws ParameterError naming the parameter when the scenario or an option is invalid
  LeaderNode(ros::NodeHandle nh, ros::NodeHandle private_nh);

 private:
  void onOdometry(const ros::MessageEvent<nav_msgs::Odometry const>& event);
  void onTick(const ros::TimerEvent& event);

  ros::NodeHandle nh_;
  std::string name_;
  Scenario scenario_;
  LeaderNodeOptions options_;
  int axes_;

  std::mutex mutex_;  ///< guards everything below against concurrent callbacks (nodelets)
  nav_msgs::Odometry odometry_;  ///< latest accepted
  Eigen::VectorXd state_;        ///< its [p; v]
  bool have_odometry_ = false;
  bool odometry_fresh_ = false;  ///< an odometry not broadcast yet
  /// Restarted by the ticks when ROS time goes back (tick_time_); an odometry older than the
  /// latest accepted is superseded.
  InputTimeline odometry_timeline_;
  TimeJumpWatch tick_time_;  ///< ROS time of the ticks published
  bool started_ = false;
  ros::Time origin_;      ///< ROS time of scenario time 0
  ros::Time last_stamp_;  ///< of the last tick published

  CountedPublisher command_publisher_;
  CountedPublisher broadcast_publisher_;
  ros::Subscriber odometry_subscriber_;
  ros::Timer timer_;
};

}  // namespace projection_collision_avoidance
