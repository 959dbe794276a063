#include "projection_collision_avoidance/ros/OdometryFrames.hpp"

#include <Eigen/Geometry>
#include <tf2/exceptions.h>
#include <tf2_eigen/tf2_eigen.h>

#include "projection_collision_avoidance/cycle/FrameNames.hpp"
#include "projection_collision_avoidance/cycle/InputGuard.hpp"
#include "projection_collision_avoidance/ros/MessageConversions.hpp"

namespace projection_collision_avoidance {

std::string ownFrameLabelReason(const std::string& frame, const std::string& frame_key) {
  const std::string name = boundedText(frame, InputGuard::kMaxQuotedLength);
  return "header.frame_id \"" + name +
         "\" is also the child_frame_id, and a frame's pose in itself is the identity (ground "
         "truth under the robot's frame?): set ~odometry/pose_frame world to take the pose in " +
         frame_key;
}

bool odometryInFrame(const nav_msgs::Odometry& msg, const std::string& world_frame,
                     bool twist_in_body_frame, PoseFrame pose_frame,
                     const tf2_ros::Buffer& tf_buffer, double tf_timeout,
                     const std::string& frame_key, OdometrySample* sample, std::string* why) {
  *sample = toOdometrySample(msg);
  if (pose_frame == PoseFrame::kWorld) {  // in the world frame, whatever the label says
    return true;
  }
  if (labelledWithItsOwnFrame(msg.header.frame_id, msg.child_frame_id)) {
    *why = ownFrameLabelReason(msg.header.frame_id, frame_key);
    return false;
  }
  if (world_frame.empty() || sameFrame(msg.header.frame_id, world_frame)) {
    return true;
  }
  geometry_msgs::TransformStamped transform;
  try {
    transform = tf_buffer.lookupTransform(tfFrame(world_frame), tfFrame(msg.header.frame_id),
                                          msg.header.stamp, ros::Duration(tf_timeout));
  } catch (const tf2::TransformException& error) {
    const std::string frame = boundedText(msg.header.frame_id, InputGuard::kMaxQuotedLength);
    *why = "no transform from \"" + frame + "\" to \"" + world_frame + "\" (" + frame_key +
           "): publish one (odometry from each robot's start pose: a static transform " +
           world_frame + " -> " + tfFrame(frame) +
           " at that start pose; global odometry: the identity), or set " + frame_key +
           " to a frame both reach: " + error.what();
    return false;
  }
  const Eigen::Isometry3d world_from_frame = tf2::transformToEigen(transform);
  const Eigen::Matrix3d rotation = world_from_frame.rotation();
  sample->position = world_from_frame * sample->position;
  sample->orientation = Eigen::Quaterniond(rotation) * sample->orientation;
  if (!twist_in_body_frame) {  // a twist in the header frame turns with it
    sample->linear_velocity = rotation * sample->linear_velocity;
    sample->angular_velocity = rotation * sample->angular_velocity;
  }
  return true;
}

}  // namespace projection_collision_avoidance
