#include "adapter/CommandFrame.hpp"

#include <utility>

#include <Eigen/Geometry>
#include <ros/console.h>
#include <tf2/exceptions.h>
#include <tf2_eigen/tf2_eigen.h>

#include "projection_collision_avoidance/cycle/FrameNames.hpp"
#include "projection_collision_avoidance/cycle/InputGuard.hpp"

namespace projection_collision_avoidance {

CommandFrame::CommandFrame(std::string node_name, const tf2_ros::Buffer* buffer,
                           bool world_from_odometry)
    : name_(std::move(node_name)), buffer_(buffer), world_from_odometry_(world_from_odometry) {}

void CommandFrame::toWorld(const std::string& command_frame, const std::string& world_frame,
                           const std::string& base_frame, double now,
                           Eigen::VectorXd* acceleration) {
  turned_ = false;
  const std::string_view frame = tfFrameName(command_frame);
  const std::string_view world = tfFrameName(world_frame);
  if (frame.empty() || world.empty() || frame == world || sameFrame(frame, base_frame)) {
    return;  // in the world's axes, or a follower's body name: as it is
  }
  if (frame != frame_ || world != world_) {  // a new pair: found afresh
    frame_.assign(frame);
    world_.assign(world);
    joined_ = false;
    warned_ = false;
    warning_.clear();
    since_ = now;
    next_lookup_ = now;
  }
  if (now >= next_lookup_) {
    lookUp(now);
  }
  if (!joined_ || acceleration->size() < 2) {
    return;
  }
  Eigen::Vector3d a = Eigen::Vector3d::Zero();
  const Eigen::Index axes = acceleration->size() < 3 ? acceleration->size() : 3;
  a.head(axes) = acceleration->head(axes);
  a = rotation_ * a;
  acceleration->head(axes) = a.head(axes);
  turned_ = true;
}

void CommandFrame::lookUp(double now) {
  try {
    // The latest rotation: a world frame and an odometry frame are joined by a fixed transform.
    if (buffer_->canTransform(world_, frame_, ros::Time())) {
      const geometry_msgs::TransformStamped transform =
          buffer_->lookupTransform(world_, frame_, ros::Time());
      rotation_ = tf2::transformToEigen(transform).rotation();
      next_lookup_ = now + kRefreshPeriod;
      if (!joined_ && warned_) {
        ROS_INFO_STREAM(name_ << ": commands in '" << frame_ << "' now turned into '" << world_
                              << "' by tf2");
      }
      joined_ = true;
      warning_.clear();
      return;
    }
  } catch (const tf2::TransformException&) {  // as a failed canTransform(): not joined (yet)
  }
  if (joined_) {  // keeps the rotation found
    next_lookup_ = now + kRefreshPeriod;
    return;
  }
  if (!warned_ && now - since_ >= kJoinGrace) {
    warned_ = true;
    warning_ = "commands in '" + boundedText(frame_, InputGuard::kMaxQuotedLength) +
               (world_from_odometry_ ? "' but the odometry in '" : "' but ~world_frame is '") +
               world_ +
               "', not joined by tf: a heading offset between them turns every command; "
               "publish the transform or set ~world_frame (a follower without a world frame "
               "names its body: give ~base_frame that name or set its ~measurement_frame)";
    ROS_WARN_STREAM(name_ << ": " << warning_);
  }
  next_lookup_ = now + (warned_ ? kRefreshPeriod : kRetryPeriod);
}

}  // namespace projection_collision_avoidance
