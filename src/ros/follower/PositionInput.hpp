#pragma once

#include <atomic>
#include <cstdint>
#include <mutex>
#include <string>

#include <geometry_msgs/PointStamped.h>
#include <geometry_msgs/PoseStamped.h>
#include <ros/ros.h>
#include <tf2_ros/buffer.h>

#include "projection_collision_avoidance/cycle/InputGuard.hpp"
#include "projection_collision_avoidance/cycle/InputTimeline.hpp"
#include "projection_collision_avoidance/cycle/TimeJumpWatch.hpp"
#include "projection_collision_avoidance/ros/GuardedTransformListener.hpp"
#include "projection_collision_avoidance/ros/InputAdmission.hpp"
#include "projection_collision_avoidance/vehicle/RelativeVelocityFilter.hpp"

#include "follower/MeasurementAdapter.hpp"

namespace projection_collision_avoidance {

/// The follower's position-only inputs (doc/vehicles.md, "Position only"): the relative position
/// p = p_target − p_self, the velocity reconstructed by a RelativeVelocityFilter
/// (~position/velocity_bandwidth), handed on as the measurement y = [p; v̂] (C = I).
/// - ~input position: `target_position` (geometry_msgs/PointStamped) or `target_pose`
///   (PoseStamped, its orientation unused): the target's position relative to the follower,
///   in header.frame_id; rotated into ~measurement_frame by tf2 when that is set and differs.
/// - ~input tf: at ~tf/rate, the latest transforms ~measurement_frame ← ~tf/self_frame and
///   ← ~tf/target_frame; the controlled points ~tf/look_ahead and ~tf/target_look_ahead ahead
///   along each body x axis; refused when their stamps differ by more than ~tf/max_skew; stamped
///   with the newer; a pair no newer than the last one used is not used again.
/// Each message or lookup is judged on its source's InputTimeline; nothing a message carries ends
/// the node.
class PositionInput : public MeasurementAdapter {
 public:
  /// @throws ParameterError naming ~position/... (the filter's checks)
  PositionInput(std::string node_name, const FollowerNodeOptions& options, int axes, Sink sink);

  void start(ros::NodeHandle nh) override;
  std::uint64_t rejected() const override { return rejected_.load(std::memory_order_relaxed); }
  /// Positions superseded (stamped at or before the latest accepted one of their topic).
  std::uint64_t superseded() const override {
    return point_timeline_.superseded() + pose_timeline_.superseded();
  }
  std::uint64_t foreignMessages() const override {
    return point_timeline_.foreignMessages() + pose_timeline_.foreignMessages();
  }
  std::int64_t foreignHeard() const override {
    return std::max(point_timeline_.foreignHeard(), pose_timeline_.foreignHeard());
  }
  std::uint64_t restarts() const override {
    return point_timeline_.restarts() + pose_timeline_.restarts() + tf_timeline_.restarts() +
           point_timeline_.handovers() + pose_timeline_.handovers();
  }
  double skew() const override { return skew_.load(std::memory_order_relaxed); }
  bool controlledPoint(std::string* frame, Eigen::Vector3d* point) override;

 private:
  /// One relative position p (m) with @p header from @p publisher, judged on @p timeline.
  void onPosition(InputTimeline* timeline, const std_msgs::Header& header, const Eigen::Vector3d& p,
                  std::string_view publisher);
  /// The ~input tf lookups.
  void onTimer(const ros::TimerEvent& event);
  /// Filters p (in the world frame, stamped @p stamp) and hands on y = [p; v̂] once estimated;
  /// false with the reason in @p why when the filter refuses it (mutex_ held).
  bool filter(const ros::Time& stamp, const std::string& frame, const Eigen::Vector3d& p,
              std::string* why);

  std::string name_;
  FollowerNodeOptions options_;
  int axes_;
  Sink sink_;
  RelativeVelocityFilter filter_;

  std::mutex mutex_;  ///< the subscriptions and the timer may call at once (nodelets)
  InputTimeline point_timeline_;
  InputTimeline pose_timeline_;
  InputTimeline tf_timeline_;
  TimeJumpWatch clock_;  ///< ROS time at every source: a jump back restarts them all
  ros::Time last_pair_stamp_;
  RelativeMeasurement measurement_;
  Eigen::VectorXd state_;
  std::atomic<std::uint64_t> rejected_{0};
  std::atomic<double> skew_;
  std::mutex point_mutex_;
  Eigen::Vector3d point_ = Eigen::Vector3d::Zero();
  bool have_point_ = false;

  tf2_ros::Buffer tf_buffer_;
  std::unique_ptr<GuardedTransformListener> tf_listener_;
  ros::Subscriber point_subscriber_;
  ros::Subscriber pose_subscriber_;
  ros::Timer timer_;
};

}  // namespace projection_collision_avoidance
