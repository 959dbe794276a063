#include "follower/OdometryInput.hpp"

#include <cmath>
#include <limits>
#include <utility>

#include "projection_collision_avoidance/cycle/FrameNames.hpp"
#include "projection_collision_avoidance/ros/GuardedTransformListener.hpp"
#include "projection_collision_avoidance/ros/OdometryFrames.hpp"

namespace projection_collision_avoidance {
namespace {

/// The parameter naming the world frame, in refusals.
constexpr const char* kFrameKey = "~measurement_frame";

OdometryAlignmentOptions alignmentOptions(const OdometryInputOptions& o, int axes) {
  OdometryAlignmentOptions a;
  a.axes = axes;
  a.max_skew = o.max_skew;
  a.quaternion_tolerance = o.quaternion_tolerance;
  // A twist in the header frame is rotated into the world frame with the pose
  // (odometryInFrame()).
  a.twist_frame = o.twist_in_body_frame ? TwistFrame::kBody : TwistFrame::kWorld;
  a.self_point = Eigen::Vector3d(o.look_ahead, 0.0, 0.0);
  a.target_point = Eigen::Vector3d(o.target_look_ahead, 0.0, 0.0);
  return a;
}

}  // namespace

OdometryInput::OdometryInput(std::string node_name, const FollowerNodeOptions& options, int axes,
                             Sink sink)
    : name_(std::move(node_name)),
      options_(options),
      axes_(axes),
      sink_(std::move(sink)),
      relative_(alignmentOptions(options.odometry, axes)),
      world_frame_(options.measurement_frame),
      // A message older than the measurement timeout on arrival could only be stale; one older
      // than the latest accepted of its topic is superseded (doc/boundary.md).
      self_("odom", InputGuardLimits{options.odom_frame, options.max_future_stamp,
                                     options.measurement_timeout, true}),
      target_("target_odom",
              InputGuardLimits{"", options.max_future_stamp, options.measurement_timeout, true}),
      skew_(std::numeric_limits<double>::quiet_NaN()) {
  pair_guard_ = InputGuard("odometry pair", {"", options.max_future_stamp, 3600.0});
}

void OdometryInput::start(ros::NodeHandle nh) {
  tf_listener_ = std::make_unique<GuardedTransformListener>(
      &tf_buffer_, nh, TransformGuardOptions{options_.max_future_stamp}, name_);
  using Event = ros::MessageEvent<nav_msgs::Odometry const>;
  self_subscriber_ = subscribeEvents<nav_msgs::Odometry>(
      nh, "odom", 10, [this](const Event& event) { onOdometry(&self_, event); });
  target_subscriber_ = subscribeEvents<nav_msgs::Odometry>(
      nh, "target_odom", 10, [this](const Event& event) { onOdometry(&target_, event); });
}

void OdometryInput::onOdometry(Side* side,
                               const ros::MessageEvent<nav_msgs::Odometry const>& event) {
  const nav_msgs::Odometry::ConstPtr& msg = event.getConstMessage();
  const std::lock_guard<std::mutex> lock(mutex_);
  InputTimeline& timeline = side->timeline;
  const std::uint64_t before = timeline.rejected();
  admitGuarded(timeline, name_, [&] {
    const ros::Time now = ros::Time::now();
    if (timeline.noteTime(nanosecondsOf(now))) {  // both sides forget the old timeline
      self_.timeline.restart();
      target_.timeline.restart();
      self_.have = target_.have = false;
    }
    if (!checkHeader(timeline, msg->header, now, publisherOf(event))) {
      return;
    }
    if (side == &self_ && options_.measurement_frame.empty()) {
      world_frame_ = tfFrame(msg->header.frame_id);  // the own odometry's frame is the world
    }
    if (options_.measurement_frame.empty() && !world_frame_.empty() && !warned_frames_ &&
        !sameFrame(msg->header.frame_id, world_frame_)) {
      warned_frames_ = true;  // the two odometries are in different frames: tf2 must join them
      ROS_WARN_STREAM(name_ << ": odom is in \"" << world_frame_ << "\", target_odom in \""
                            << boundedText(msg->header.frame_id, InputGuard::kMaxQuotedLength)
                            << "\": moved into the first with tf2; set ~measurement_frame to "
                               "the frame both robots' odometry frames reach (their starts "
                               "placed by tf), as odometry from different start poses has no "
                               "common origin otherwise");
    }
    std::string why;
    OdometrySample sample;
    if (!odometryInFrame(*msg, world_frame_, options_.odometry.twist_in_body_frame,
                         options_.odometry.pose_frame, tf_buffer_, options_.odometry.tf_timeout,
                         kFrameKey, &sample, &why)) {
      timeline.reject(Rejection::kContent, why);
      return;
    }
    timeline.accept();
    side->sample = sample;
    side->frame = world_frame_.empty() ? tfFrame(msg->header.frame_id) : world_frame_;
    side->msg = msg;
    side->stamp = msg->header.stamp;
    side->have = true;
    if (side == &self_) {
      const std::lock_guard<std::mutex> point_lock(point_mutex_);
      point_ =
          bodyPointState(sample, relative_.options().self_point, relative_.options().twist_frame)
              .head<3>();
      world_frame_copy_ = world_frame_;
      have_point_ = true;
      combine();  // each own odometry makes a measurement, with the latest of the target's
    }
  });
  rejected_.fetch_add(timeline.rejected() - before, std::memory_order_relaxed);
}

bool OdometryInput::controlledPoint(std::string* frame, Eigen::Vector3d* point) {
  const std::lock_guard<std::mutex> lock(point_mutex_);
  if (!have_point_) {
    return false;
  }
  *frame = world_frame_copy_;
  *point = point_;
  return true;
}

void OdometryInput::combine() {
  if (!self_.have || !target_.have) {
    return;
  }
  if (target_.frame != world_frame_) {  // the world frame changed since the target's arrival
    std::string why;
    OdometrySample sample;
    if (!odometryInFrame(*target_.msg, world_frame_, options_.odometry.twist_in_body_frame,
                         options_.odometry.pose_frame, tf_buffer_, options_.odometry.tf_timeout,
                         kFrameKey, &sample, &why)) {
      rejected_pairs_.fetch_add(1, std::memory_order_relaxed);
      pair_guard_.reject(Rejection::kContent, "the target's odometry: " + why);
      logRejection(pair_guard_, name_);
      return;
    }
    target_.sample = sample;
    target_.frame = world_frame_;
  }
  const RelativeOdometryResult result = relative_.compute(self_.sample, target_.sample);
  if (!result.accepted()) {
    rejected_pairs_.fetch_add(1, std::memory_order_relaxed);
    pair_guard_.reject(Rejection::kContent,
                       std::string("the odometry pair is refused: ") + toString(result.verdict) +
                           (result.verdict == OdometryVerdict::kSkewTooLarge
                                ? " (" + std::to_string(result.skew) + " s > ~odometry/max_skew)"
                                : std::string()));
    logRejection(pair_guard_, name_);
    return;
  }
  skew_.store(result.skew, std::memory_order_relaxed);
  measurement_.header.stamp = self_.stamp > target_.stamp ? self_.stamp : target_.stamp;
  measurement_.header.frame_id = world_frame_;
  measurement_.position.resize(static_cast<std::size_t>(axes_));
  measurement_.velocity.resize(static_cast<std::size_t>(axes_));
  for (int i = 0; i < axes_; ++i) {
    measurement_.position[static_cast<std::size_t>(i)] = result.state(i);
    measurement_.velocity[static_cast<std::size_t>(i)] = result.state(axes_ + i);
  }
  sink_(measurement_);
}

}  // namespace projection_collision_avoidance
