#pragma once

/// @file
/// An odometry message brought into another world frame with tf2: the one frame change the
/// follower's odometry input and the command adapter share.

#include <string>

#include <nav_msgs/Odometry.h>
#include <tf2_ros/buffer.h>

#include "projection_collision_avoidance/vehicle/RelativeStateFromOdometry.hpp"

namespace projection_collision_avoidance {

/// Why an odometry whose header.frame_id is also its child_frame_id (@p frame) is refused with
/// ~odometry/pose_frame header; @p frame_key names the world frame parameter to pair it with.
std::string ownFrameLabelReason(const std::string& frame, const std::string& frame_key);

/// @p msg as an OdometrySample in @p world_frame: unchanged when its header.frame_id is that
/// frame (or @p world_frame is empty), or with @p pose_frame kWorld whatever header.frame_id says;
/// refused with @p pose_frame kHeader when header.frame_id is also child_frame_id
/// (labelledWithItsOwnFrame(): the reason names ~odometry/pose_frame); otherwise pose
/// (p_W = T p, q_W = R q) and, for a twist in the header frame (@p twist_in_body_frame false), the
/// twist (v_W = R v, ω_W = R ω) moved by the transform world ← header.frame_id that @p tf_buffer
/// holds at the message's stamp, waiting at most @p tf_timeout s. A body-frame twist stays as it
/// is (its body now has orientation q_W).
/// @param frame_key the parameter that names @p world_frame (`~measurement_frame`,
///        `~world_frame`), named in the reason with the transform to publish
/// @return false, with the reason in @p why, when there is no such transform or the message is
///         labelled with its own frame
bool odometryInFrame(const nav_msgs::Odometry& msg, const std::string& world_frame,
                     bool twist_in_body_frame, PoseFrame pose_frame,
                     const tf2_ros::Buffer& tf_buffer, double tf_timeout,
                     const std::string& frame_key, OdometrySample* sample, std::string* why);

}  // namespace projection_collision_avoidance
