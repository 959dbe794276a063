#include "follower/PositionInput.hpp"

#include <cmath>
#include <limits>
#include <string>
#include <utility>

#include <Eigen/Geometry>
#include <tf2/exceptions.h>
#include <tf2_eigen/tf2_eigen.h>

#include "projection_collision_avoidance/core/ParameterError.hpp"
#include "projection_collision_avoidance/cycle/FrameNames.hpp"
#include "projection_collision_avoidance/ros/GuardedTransformListener.hpp"
#include "projection_collision_avoidance/ros/MessageConversions.hpp"

namespace projection_collision_avoidance {
namespace {

RelativeVelocityFilter makeFilter(const PositionInputOptions& o, int axes) {
  VelocityFilterOptions f;
  f.axes = axes;
  f.bandwidth = o.velocity_bandwidth;
  f.max_gap = o.max_gap;
  f.min_interval = o.min_interval;
  f.max_speed = o.max_speed;
  try {
    return RelativeVelocityFilter(f);
  } catch (const std::invalid_argument& error) {
    // The message begins with the option's name.
    const std::string what = error.what();
    const std::string option = what.substr(0, what.find(' '));
    throw ParameterError(
        "~position/" + (option == "bandwidth" ? std::string("velocity_bandwidth") : option),
        error.what());
  }
}

Eigen::Vector3d vectorOf(const geometry_msgs::Point& p) { return {p.x, p.y, p.z}; }

}  // namespace

PositionInput::PositionInput(std::string node_name, const FollowerNodeOptions& options, int axes,
                             Sink sink)
    : name_(std::move(node_name)),
      options_(options),
      axes_(axes),
      sink_(std::move(sink)),
      filter_(makeFilter(options.position, axes)),
      // Positions are a state stream: an older one than the latest is superseded.
      point_timeline_("target_position", InputGuardLimits{"", options.max_future_stamp,
                                                          options.measurement_timeout, true}),
      pose_timeline_("target_pose", InputGuardLimits{"", options.max_future_stamp,
                                                     options.measurement_timeout, true}),
      tf_timeline_("tf lookup",
                   InputGuardLimits{"", options.max_future_stamp, options.measurement_timeout}),
      skew_(std::numeric_limits<double>::quiet_NaN()) {}

void PositionInput::start(ros::NodeHandle nh) {
  tf_listener_ = std::make_unique<GuardedTransformListener>(
      &tf_buffer_, nh, TransformGuardOptions{options_.max_future_stamp}, name_);
  if (options_.input == MeasurementInput::kTf) {
    timer_ =
        nh.createTimer(ros::Duration(1.0 / options_.position.rate), &PositionInput::onTimer, this);
    return;
  }
  point_subscriber_ = subscribeEvents<geometry_msgs::PointStamped>(
      nh, "target_position", 10,
      [this](const ros::MessageEvent<geometry_msgs::PointStamped const>& event) {
        const geometry_msgs::PointStamped& msg = *event.getConstMessage();
        onPosition(&point_timeline_, msg.header, vectorOf(msg.point), publisherOf(event));
      });
  pose_subscriber_ = subscribeEvents<geometry_msgs::PoseStamped>(
      nh, "target_pose", 10,
      [this](const ros::MessageEvent<geometry_msgs::PoseStamped const>& event) {
        const geometry_msgs::PoseStamped& msg = *event.getConstMessage();
        onPosition(&pose_timeline_, msg.header, vectorOf(msg.pose.position), publisherOf(event));
      });
}

bool PositionInput::controlledPoint(std::string* frame, Eigen::Vector3d* point) {
  const std::lock_guard<std::mutex> lock(point_mutex_);
  if (!have_point_) {
    return false;
  }
  *frame = options_.measurement_frame;
  *point = point_;
  return true;
}

void PositionInput::onPosition(InputTimeline* timeline, const std_msgs::Header& header,
                               const Eigen::Vector3d& p, std::string_view publisher) {
  const std::lock_guard<std::mutex> lock(mutex_);
  const std::uint64_t before = timeline->rejected();
  admitGuarded(*timeline, name_, [&] {
    const ros::Time now = ros::Time::now();
    if (wentBack(clock_, now)) {  // every source forgets the old timeline
      point_timeline_.restart();
      pose_timeline_.restart();
      filter_.reset();
    }
    if (!checkHeader(*timeline, header, now, publisher)) {
      return;
    }
    if (!p.allFinite()) {
      timeline->reject(Rejection::kContent, "non-finite position");
      return;
    }
    Eigen::Vector3d world = p;
    const std::string& world_frame = options_.measurement_frame;
    if (!world_frame.empty() && !sameFrame(header.frame_id, world_frame)) {
      // p is a vector between two points: only the rotation world ← frame acts on it.
      geometry_msgs::TransformStamped transform;
      try {
        transform = tf_buffer_.lookupTransform(world_frame, tfFrame(header.frame_id), header.stamp,
                                               ros::Duration(options_.position.tf_timeout));
      } catch (const tf2::TransformException& error) {
        timeline->reject(Rejection::kContent,
                         "no transform from \"" +
                             boundedText(header.frame_id, InputGuard::kMaxQuotedLength) +
                             "\" to \"" + world_frame + "\": " + error.what());
        return;
      }
      world = tf2::transformToEigen(transform).rotation() * p;
    }
    std::string why;
    if (!filter(header.stamp, world_frame.empty() ? tfFrame(header.frame_id) : world_frame, world,
                &why)) {
      timeline->reject(Rejection::kContent, why);
      return;
    }
    timeline->accept();
  });
  rejected_.fetch_add(timeline->rejected() - before, std::memory_order_relaxed);
}

void PositionInput::onTimer(const ros::TimerEvent& /*event*/) {
  const std::lock_guard<std::mutex> lock(mutex_);
  const std::uint64_t before = tf_timeline_.rejected();
  admitGuarded(tf_timeline_, name_, [&] {
    const ros::Time now = ros::Time::now();
    if (wentBack(clock_, now)) {
      tf_timeline_.restart();
      last_pair_stamp_ = ros::Time();
      filter_.reset();
    }
    const PositionInputOptions& o = options_.position;
    const std::string& world = options_.measurement_frame;
    geometry_msgs::TransformStamped self;
    geometry_msgs::TransformStamped target;
    if (!tf_buffer_.canTransform(world, o.self_frame, ros::Time()) ||
        !tf_buffer_.canTransform(world, o.target_frame, ros::Time())) {
      return;  // not yet (or no longer) both in the tree: nothing to judge
    }
    try {
      self = tf_buffer_.lookupTransform(world, o.self_frame, ros::Time());
      target = tf_buffer_.lookupTransform(world, o.target_frame, ros::Time());
    } catch (const tf2::TransformException& error) {
      tf_timeline_.reject(Rejection::kContent, error.what());
      return;
    }
    const ros::Time stamp = std::max(self.header.stamp, target.header.stamp);
    if (stamp <= last_pair_stamp_) {
      return;  // nothing new since the last lookup
    }
    last_pair_stamp_ = stamp;
    std_msgs::Header header;
    header.stamp = stamp;
    header.frame_id = world;
    if (!checkHeader(tf_timeline_, header, now)) {
      return;
    }
    const double skew = std::abs(secondsBetween(self.header.stamp, target.header.stamp));
    if (skew > o.max_skew) {
      tf_timeline_.reject(
          Rejection::kContent,
          "the transforms' stamps are " + std::to_string(skew) + " s apart (> ~tf/max_skew)");
      return;
    }
    const Eigen::Isometry3d world_self = tf2::transformToEigen(self);
    const Eigen::Isometry3d world_target = tf2::transformToEigen(target);
    const Eigen::Vector3d self_point = world_self * Eigen::Vector3d(o.look_ahead, 0.0, 0.0);
    const Eigen::Vector3d target_point =
        world_target * Eigen::Vector3d(o.target_look_ahead, 0.0, 0.0);
    {
      const std::lock_guard<std::mutex> point_lock(point_mutex_);
      point_ = self_point;
      have_point_ = self_point.allFinite();
    }
    std::string why;
    if (!filter(stamp, world, target_point - self_point, &why)) {
      tf_timeline_.reject(Rejection::kContent, why);
      return;
    }
    skew_.store(skew, std::memory_order_relaxed);
    tf_timeline_.accept();
  });
  rejected_.fetch_add(tf_timeline_.rejected() - before, std::memory_order_relaxed);
}

bool PositionInput::filter(const ros::Time& stamp, const std::string& frame,
                           const Eigen::Vector3d& p, std::string* why) {
  const VelocityFilterVerdict verdict = filter_.update(stamp.toSec(), p, &state_);
  if (verdict == VelocityFilterVerdict::kRefused ||
      verdict == VelocityFilterVerdict::kNotIncreasing ||
      verdict == VelocityFilterVerdict::kTooFast) {
    *why = std::string("the velocity filter refused the position: ") + toString(verdict) +
           (verdict == VelocityFilterVerdict::kTooFast ? " (beyond ~position/max_speed)" : "");
    return false;
  }
  if (verdict != VelocityFilterVerdict::kEstimated) {
    // The first position (no velocity yet), or one too soon after the last used: not a fault
    // of the sender (a sensor faster than ~position/min_interval), simply not used.
    return true;
  }
  measurement_.header.stamp = stamp;
  measurement_.header.frame_id = frame;
  measurement_.position.resize(static_cast<std::size_t>(axes_));
  measurement_.velocity.resize(static_cast<std::size_t>(axes_));
  for (int i = 0; i < axes_; ++i) {
    measurement_.position[static_cast<std::size_t>(i)] = state_(i);
    measurement_.velocity[static_cast<std::size_t>(i)] = state_(axes_ + i);
  }
  sink_(measurement_);
  return true;
}

}  // namespace projection_collision_avoidance
