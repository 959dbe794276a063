#pragma once

#include <string>

#include "projection_collision_avoidance/ros/RosParameters.hpp"
#include "projection_collision_avoidance/vehicle/CommandConverter.hpp"

namespace projection_collision_avoidance {

/// The command adapter's options, read once from its private namespace (doc/vehicles.md).
struct CommandAdapterOptions {
  bool accel_enu = false;      ///< ~outputs has "accel_enu": `setpoint_accel` (Vector3Stamped)
  bool twist = false;          ///< "twist": `cmd_vel` (Twist), the velocity command
  bool twist_stamped = false;  ///< "twist_stamped": `cmd_vel_stamped` (TwistStamped)
  bool unicycle = false;       ///< "unicycle": `cmd_vel` (Twist: linear.x = v, angular.z = ω)
  CommandConverterOptions converter;
  double command_timeout = 0.25;  ///< steady s without a command before the stop is sent
  double watchdog_rate = 20.0;    ///< Hz (steady time) of the timeout checks and repeated stops
  /// s a command's or an odometry's stamp may lie ahead of this node's clock (two 100 ms bursts
  /// of a simulated /clock and 50 ms of transport; doc/boundary.md)
  double max_future_stamp = 0.25;
  std::string base_frame;  ///< frame_id of base-frame stamped outputs ("": the odometry's child)
  /// The follower's world frame (its measurements' frame); "": the own odometry's header frame.
  std::string world_frame;
  /// ~odometry/pose_frame: the own odometry's pose in its header.frame_id, or in world_frame.
  PoseFrame pose_frame = PoseFrame::kHeader;
};

/// The options, each validated (the message names the key): ~outputs (a space-separated set of
/// accel_enu, twist, twist_stamped, unicycle; twist and unicycle both publish cmd_vel and are
/// refused together), ~axes, ~control_rate, ~command_timeout, ~watchdog_rate, ~max_future_stamp,
/// ~odometry/max_age, ~odometry/twist_frame, ~odometry/pose_frame ("world" needs ~world_frame),
/// ~velocity/max_speed, ~velocity/lag, ~velocity/delay, ~velocity/max_delay,
/// ~velocity/averaging_time, ~velocity/frame, ~unicycle/look_ahead, ~unicycle/max_speed,
/// ~unicycle/max_yaw_rate, ~stop_deceleration, ~base_frame, ~world_frame. The speed and yaw-rate
/// limits are finite (4 m/s, 3 rad/s by default; at most 1e4): every output is within them.
CommandAdapterOptions readCommandAdapterOptions(NodeOptionReader& reader);

}  // namespace projection_collision_avoidance
