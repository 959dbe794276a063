#pragma once

#include <atomic>
#include <cstdint>
#include <mutex>
#include <string>
#include <thread>

#include <ros/callback_queue.h>
#include <ros/ros.h>
#include <tf2_msgs/TFMessage.h>
#include <tf2_ros/buffer.h>

#include "projection_collision_avoidance/cycle/InputGuard.hpp"
#include "projection_collision_avoidance/cycle/TimeJumpWatch.hpp"

namespace projection_collision_avoidance {

/// What a GuardedTransformListener lets into its buffer.
struct TransformGuardOptions {
  /// s a transform may be stamped ahead of this node's clock (~max_future_stamp)
  double max_future_stamp = 0.25;
};

/// tf2_ros::TransformListener with the boundary contract (doc/boundary.md, "tf"): it subscribes
/// `/tf` and `/tf_static` and hands each transform to the buffer only when its stamp is not zero
/// (dynamic ones), lies at most max_future_stamp ahead of ROS time and within the buffer's cache
/// time behind it, its frames are named, and its translation and rotation are finite (the
/// rotation a quaternion of norm within 1e-3 of 1). One transform stamped far ahead would
/// otherwise become the newest of its frame in the buffer, and every real one after it "old
/// data" for the cache time (TF_OLD_DATA, a lookup at time 0 answered with the forged one).
/// Refusals are counted and logged at most once a second by kind, then once a minute (InputGuard).
/// When ROS time goes back the buffer is cleared, as tf2_ros::TransformListener does. As that
/// listener, it takes the messages on a callback queue and thread of its own, so that a lookup
/// that waits (a tf timeout) in another callback does not hold the transforms back.
class GuardedTransformListener {
 public:
  /// Subscribes `/tf` and `/tf_static` (absolute names, as tf2_ros) with @p nh; @p buffer outlives
  /// this.
  GuardedTransformListener(tf2_ros::Buffer* buffer, ros::NodeHandle nh,
                           const TransformGuardOptions& options, std::string node_name);
  ~GuardedTransformListener();
  GuardedTransformListener(const GuardedTransformListener&) = delete;
  GuardedTransformListener& operator=(const GuardedTransformListener&) = delete;

  /// Transforms refused so far (any thread).
  std::uint64_t rejected() const { return rejected_.load(std::memory_order_relaxed); }

 private:
  void onMessage(const ros::MessageEvent<tf2_msgs::TFMessage const>& event, bool is_static);
  /// The refusal of @p t at @p now, or "" when it may enter the buffer.
  bool admit(const geometry_msgs::TransformStamped& t, std::int64_t now_ns, bool is_static);

  tf2_ros::Buffer* buffer_;
  TransformGuardOptions options_;
  std::string name_;
  std::mutex mutex_;
  InputGuard guard_;
  TimeJumpWatch clock_;
  std::atomic<std::uint64_t> rejected_{0};
  ros::CallbackQueue queue_;
  ros::Subscriber dynamic_subscriber_;
  ros::Subscriber static_subscriber_;
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

}  // namespace projection_collision_avoidance
