#pragma once

#include <cstdint>
#include <memory>
#include <mutex>
#include <string>

#include <diagnostic_updater/diagnostic_updater.h>
#include <geometry_msgs/AccelStamped.h>
#include <nav_msgs/Odometry.h>
#include <ros/ros.h>
#include <tf2_ros/buffer.h>

#include "projection_collision_avoidance/cycle/InputGuard.hpp"
#include "projection_collision_avoidance/cycle/InputTimeline.hpp"
#include "projection_collision_avoidance/ros/GuardedTransformListener.hpp"
#include "projection_collision_avoidance/ros/InputAdmission.hpp"
#include "projection_collision_avoidance/vehicle/CommandConverter.hpp"
#include "projection_collision_avoidance/vehicle/OutputWatchdog.hpp"

namespace projection_collision_avoidance {

struct CommandAdapterOptions;
class CommandFrame;

/// The follower's command for a vehicle stack (node `command_adapter`, nodelet
/// CommandAdapterNodelet; doc/vehicles.md). Subscribes `command` (geometry_msgs/AccelStamped:
/// the follower's acceleration in the axes of its frame_id, turned into the world frame by tf2
/// when it names another frame than the world and the base frame: CommandFrame) and the vehicle's
/// own `odom` (nav_msgs/Odometry: heading and measured velocity, twist in child_frame_id as REP 105
/// says; moved into ~world_frame with tf2 when that is set and its frame differs) and publishes,
/// for each command, the ~outputs chosen: `setpoint_accel` (geometry_msgs/Vector3Stamped, the
/// acceleration in the world frame, ENU as MAVROS's setpoint_accel plugin takes it),
/// `cmd_vel` (geometry_msgs/Twist: the velocity command, world or base frame, or a unicycle's
/// v and ω) and `cmd_vel_stamped` (geometry_msgs/TwistStamped). CommandConverter makes them.
///
/// Command timeout: a steady-clock timer at ~watchdog_rate checks OutputWatchdog; once no
/// command has come for ~command_timeout (the follower stopped, crashed, or its simulated clock
/// stands still) every output gets its stop (zero velocity, zero v and ω, a braking
/// acceleration), again at every check until commands return. Commands that are non-finite, act
/// on an axis the model lacks, or are stamped 0, in the future or not after the last one, are
/// refused and counted (InputTimeline); so are non-finite odometry messages; an odometry stamped
/// at or before the latest accepted one is superseded (dropped, counted apart). The counts are in
/// `/diagnostics`. No input ends the node.
class CommandAdapter {
 public:
  /// @throws ParameterError naming the key of an invalid option
  CommandAdapter(ros::NodeHandle nh, ros::NodeHandle private_nh);
  ~CommandAdapter();
  CommandAdapter(const CommandAdapter&) = delete;
  CommandAdapter& operator=(const CommandAdapter&) = delete;

 private:
  void onCommand(const ros::MessageEvent<geometry_msgs::AccelStamped const>& event);
  void onOdometry(const ros::MessageEvent<nav_msgs::Odometry const>& event);
  void onWatchdog(const ros::SteadyTimerEvent& event);
  /// The counts of both inputs for `/diagnostics` (mutex_ held).
  void diagnose(diagnostic_updater::DiagnosticStatusWrapper& status);
  /// Publishes @p command on every chosen output, stamped @p stamp (mutex_ held): the one place
  /// where output messages are filled. A command the converter replaced by its stop (not
  /// finite) is counted; one not finite still is not published (counted too).
  void publish(const ConvertedCommand& command, const ros::Time& stamp);

  std::string name_;
  std::unique_ptr<CommandAdapterOptions> options_;
  std::mutex mutex_;  ///< the callbacks may run at once (nodelets)
  CommandConverter converter_;
  OutputWatchdog watchdog_;
  InputTimeline command_timeline_;
  InputTimeline odometry_timeline_;
  std::string world_frame_;  ///< ~world_frame, or the own odometry's header.frame_id
  std::string base_frame_;   ///< ~base_frame, or the own odometry's child_frame_id
  Eigen::VectorXd acceleration_;
  bool warned_no_base_frame_ = false;
  std::uint64_t replaced_outputs_ = 0;           ///< non-finite conversions sent as the stop
  std::uint64_t unpublished_outputs_ = 0;        ///< non-finite commands not published
  std::unique_ptr<CommandFrame> command_frame_;  ///< the command's frame into world_frame_
  /// `/diagnostics` at 1 Hz of ROS time, from the watchdog's timer: accepted, rejected and
  /// superseded messages of `command` and `odom`.
  diagnostic_updater::Updater diagnostics_;

  tf2_ros::Buffer tf_buffer_;
  std::unique_ptr<GuardedTransformListener> tf_listener_;
  ros::Publisher accel_publisher_;
  ros::Publisher twist_publisher_;
  ros::Publisher twist_stamped_publisher_;
  ros::Subscriber command_subscriber_;
  ros::Subscriber odometry_subscriber_;
  ros::SteadyTimer watchdog_timer_;
};

}  // namespace projection_collision_avoidance
