#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <mutex>
#include <string>

#include <nav_msgs/Odometry.h>
#include <ros/ros.h>
#include <tf2_ros/buffer.h>

#include "projection_collision_avoidance/RelativeMeasurement.h"
#include "projection_collision_avoidance/cycle/InputGuard.hpp"
#include "projection_collision_avoidance/cycle/InputTimeline.hpp"
#include "projection_collision_avoidance/ros/GuardedTransformListener.hpp"
#include "projection_collision_avoidance/ros/InputAdmission.hpp"
#include "projection_collision_avoidance/vehicle/RelativeStateFromOdometry.hpp"

#include "follower/FollowerOptions.hpp"
#include "follower/MeasurementAdapter.hpp"

namespace projection_collision_avoidance {

/// The follower's `odometry` input (~input odometry; doc/vehicles.md): subscribes its own
/// `odom` and its target's `target_odom` (nav_msgs/Odometry, REP 105: pose in header.frame_id,
/// twist in child_frame_id), judges each on its InputTimeline, brings both into one world frame
/// (~measurement_frame, else the own odometry's header.frame_id) with tf2 when a frame differs
/// (with ~odometry/pose_frame world: taken in ~measurement_frame as they are; with header, one
/// whose header.frame_id is its child_frame_id is refused), and, at every accepted own odometry,
/// turns it and the target's latest into the relative state x_target − x_self of the controlled
/// points (RelativeStateFromOdometry: the older sample moved to the newer stamp at constant
/// velocity, a skew beyond ~odometry/max_skew refused; the points ~odometry/look_ahead and
/// ~odometry/target_look_ahead ahead of each origin along its body x axis). The result goes to @p
/// sink as a RelativeMeasurement stamped with the newer stamp, in the world frame, to be judged
/// like any measurement. Nothing a message carries ends the node.
class OdometryInput : public MeasurementAdapter {
 public:
  /// @param axes of the model (2 or 3)
  /// @throws ParameterError naming ~odometry/... (RelativeStateFromOdometry's checks)
  OdometryInput(std::string node_name, const FollowerNodeOptions& options, int axes, Sink sink);

  /// Subscribes `odom` and `target_odom` (once the sink's receiver is in place).
  void start(ros::NodeHandle nh) override;

  /// Odometry messages refused so far (both topics), and pairs of accepted messages refused by
  /// the alignment (skew, non-unit quaternion, no transform, ...).
  std::uint64_t rejected() const override {
    return rejected_.load(std::memory_order_relaxed) +
           rejected_pairs_.load(std::memory_order_relaxed);
  }
  /// Odometry messages superseded so far (both topics): stamped at or before the latest accepted.
  std::uint64_t superseded() const override {
    return self_.timeline.superseded() + target_.timeline.superseded();
  }
  std::uint64_t foreignMessages() const override {
    return self_.timeline.foreignMessages() + target_.timeline.foreignMessages();
  }
  std::int64_t foreignHeard() const override {
    return std::max(self_.timeline.foreignHeard(), target_.timeline.foreignHeard());
  }
  std::uint64_t restarts() const override {
    return self_.timeline.restarts() + target_.timeline.restarts() + self_.timeline.handovers() +
           target_.timeline.handovers();
  }
  /// The world frame and the world position (m) of the own controlled point at the latest own
  /// odometry; false before one.
  bool controlledPoint(std::string* frame, Eigen::Vector3d* point) override;
  /// The latest |t_target − t_self| of an aligned pair (s); NaN before one.
  double skew() const override { return skew_.load(std::memory_order_relaxed); }

 private:
  /// One agent's side: its input's timeline and latest accepted sample (world frame).
  struct Side {
    Side(std::string topic, const InputGuardLimits& limits) : timeline(std::move(topic), limits) {}
    InputTimeline timeline;
    OdometrySample sample;  ///< in `frame`
    std::string frame;
    nav_msgs::Odometry::ConstPtr msg;  ///< as received
    ros::Time stamp;
    bool have = false;
  };

  void onOdometry(Side* side, const ros::MessageEvent<nav_msgs::Odometry const>& event);
  /// The relative state of the latest pair to the sink (mutex_ held), or a refusal counted.
  void combine();

  std::string name_;
  FollowerNodeOptions options_;
  int axes_;
  Sink sink_;
  RelativeStateFromOdometry relative_;
  std::string world_frame_;     ///< ~measurement_frame, else the latest own odometry's frame
  bool warned_frames_ = false;  ///< the odometries' frames differ without ~measurement_frame

  std::mutex mutex_;  ///< the two subscriptions may call at once (nodelets)
  Side self_;
  Side target_;
  std::mutex point_mutex_;  ///< the own controlled point, read by the outputs (never nested)
  Eigen::Vector3d point_ = Eigen::Vector3d::Zero();
  std::string world_frame_copy_;
  bool have_point_ = false;
  InputGuard pair_guard_;  ///< counts and logs the pairs the alignment refuses
  RelativeMeasurement measurement_;
  std::atomic<std::uint64_t> rejected_{0};
  std::atomic<std::uint64_t> rejected_pairs_{0};
  std::atomic<double> skew_;

  tf2_ros::Buffer tf_buffer_;
  std::unique_ptr<GuardedTransformListener> tf_listener_;
  ros::Subscriber self_subscriber_;
  ros::Subscriber target_subscriber_;
};

}  // namespace projection_collision_avoidance
