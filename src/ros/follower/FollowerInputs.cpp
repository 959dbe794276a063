#include "follower/FollowerInputs.hpp"

#include <algorithm>
#include <utility>

#include "projection_collision_avoidance/cycle/FrameNames.hpp"
#include "projection_collision_avoidance/ros/MessageConversions.hpp"
#include "projection_collision_avoidance/ros/OdometryFrames.hpp"

namespace projection_collision_avoidance {

FollowerInputs::FollowerInputs(std::string node_name, const FollowerNodeOptions& options,
                               const ControllerDesign& design, FollowerCycle* cycle,
                               AcceptedSink on_accepted)
    : name_(std::move(node_name)),
      options_(options),
      design_(design),
      axes_(design.parameters.model.double_integrator_axes),
      cycle_(cycle),
      on_accepted_(std::move(on_accepted)),
      // A message older than its timeout on arrival could only be stale: refused as such.
      measurement_timeline_(
          "relative_measurement",
          {{options.measurement_frame, options.max_future_stamp, options.measurement_timeout},
           options.clock_skew}),
      leader_timeline_("leader_broadcast", {{options.leader_broadcast_frame,
                                             options.max_future_stamp, options.leader_timeout},
                                            options.clock_skew}),
      // The own odometry: stamps as they are; an older one than the latest is superseded.
      odometry_timeline_("odom", InputGuardLimits{options.odom_frame, options.max_future_stamp,
                                                  options.measurement_timeout, true}) {
  measurement_.relative_state.setZero(2 * axes_);
  leader_.acceleration.setZero(axes_);
  own_state_.state.setZero(2 * axes_);
  own_state_.controlled_velocity.setZero(axes_);
  own_state_.controlled_position.setZero(axes_);
  relative_state_ = Eigen::VectorXd::Zero(2 * axes_);
  odometry_state_ = Eigen::VectorXd::Zero(2 * axes_);
  if (options.neighbours) {
    neighbours_ = std::make_unique<NeighbourInput>(name_, options, axes_, &cycle->neighbours());
  }
}

void FollowerInputs::start(ros::NodeHandle node) {
  // Each callback only judges a message and writes it into a lock-free slot: it runs on the
  // thread that read the message (InlineCallbackQueue), with no wake-up of a spinner.
  ros::NodeHandle nh(node);
  nh.setCallbackQueue(&inline_queue_);
  // ~transport udp: UDPROS where the publisher offers it (roscpp does, rospy does not), else TCP.
  const ros::TransportHints link = options_.transport == Transport::kUdp
                                       ? ros::TransportHints().unreliable().reliable().tcpNoDelay()
                                       : ros::TransportHints().tcpNoDelay();
  if (options_.input == MeasurementInput::kRelativeMeasurement) {
    measurement_subscriber_ =
        nh.subscribe("relative_measurement", 10, &FollowerInputs::onMeasurement, this, link);
  }
  leader_subscriber_ =
      nh.subscribe("leader_broadcast", 10, &FollowerInputs::onLeaderBroadcast, this, link);
  if (design_.parameters.time_headway > 0.0 || options_.turning || options_.path) {
    odometry_subscriber_ = nh.subscribe("odom", 10, &FollowerInputs::onOdometry, this,
                                        ros::TransportHints().tcpNoDelay());
  }
  if (neighbours_) {
    neighbours_->start(nh, link);
  }
}

FollowerInputStats FollowerInputs::stats(std::int64_t now_ns) const {
  FollowerInputStats stats;
  stats.measurement_age = measurement_timeline_.age(now_ns);
  stats.leader_age = leader_timeline_.age(now_ns);
  stats.rejected_measurements = measurement_timeline_.rejected();
  stats.rejected_leader_broadcasts = leader_timeline_.rejected();
  stats.rejected_odometry = odometry_timeline_.rejected();
  stats.superseded_odometry = odometry_timeline_.superseded();
  stats.measurement_skew = measurement_timeline_.skew();
  stats.leader_skew = leader_timeline_.skew();
  stats.clock_offset = clock_offset_.load(std::memory_order_relaxed);
  if (neighbours_) {
    const InputTimeline& timeline = neighbours_->timeline();
    stats.rejected_neighbours = timeline.rejected();
    stats.neighbours_age = timeline.age(now_ns);
    stats.neighbour_rejection = neighbours_->rejection();
  }
  for (const InputTimeline* timeline :
       {&measurement_timeline_, &leader_timeline_, &odometry_timeline_,
        neighbours_ ? &neighbours_->timeline() : nullptr}) {
    if (timeline == nullptr) {
      continue;
    }
    stats.foreign_messages += timeline->foreignMessages();
    stats.foreign_heard_ns = std::max(stats.foreign_heard_ns, timeline->foreignHeard());
    stats.input_restarts += timeline->restarts();
    stats.input_handovers += timeline->handovers();
  }
  if (const MeasurementAdapter* adapter = adapter_.load(std::memory_order_acquire)) {
    stats.rejected_input = adapter->rejected();
    stats.superseded_input = adapter->superseded();
    stats.input_skew = adapter->skew();
    stats.foreign_messages += adapter->foreignMessages();
    stats.foreign_heard_ns = std::max(stats.foreign_heard_ns, adapter->foreignHeard());
    stats.input_restarts += adapter->restarts();
  }
  const std::lock_guard<std::mutex> lock(reasons_mutex_);
  stats.measurement_rejection = measurement_rejection_;
  stats.leader_rejection = leader_rejection_;
  return stats;
}

void FollowerInputs::commandFrame(std::string* frame) const {
  if (!options_.measurement_frame.empty()) {  // every accepted measurement carries it
    *frame = options_.measurement_frame;
    return;
  }
  const std::lock_guard<std::mutex> lock(reasons_mutex_);
  *frame = command_frame_;
}

void FollowerInputs::onMeasurement(const ros::MessageEvent<RelativeMeasurement const>& event) {
  admitMeasurement(*event.getConstMessage(), publisherOf(event));
}

void FollowerInputs::admitMeasurement(const RelativeMeasurement& measurement,
                                      std::string_view publisher) {
  const RelativeMeasurement* msg = &measurement;
  InputTimeline& timeline = measurement_timeline_;
  admitGuarded(timeline, name_, [&] {
    const ros::Time now = ros::Time::now();
    // A jump back of ROS time restarts the timeline (the control cycle notes and reports the jump
    // itself); the header is judged on the sender's clock (~clock_skew/policy).
    if (!checkHeader(timeline, msg->header, now, publisher)) {
      if (timeline.guard().lastKind() == Rejection::kFuture) {
        cycle_->noteFutureMeasurement();  // this clock may still be catching up after a stall
      }
      return;
    }
    std::string why;
    if (!relativeStateFromMsg(*msg, axes_, &relative_state_, &why)) {
      timeline.reject(Rejection::kContent, why);
      return;
    }
    const std::int64_t raw = nanosecondsOf(msg->header.stamp);
    // The periods between this stamp and the last accepted one's (for the measurement trigger).
    const InputGuard& guard = timeline.guard();
    const std::uint32_t skipped =
        guard.haveAccepted()
            ? skippedPeriods(1e-9 * static_cast<double>(raw - guard.lastStamp()), design_.period)
            : 0;
    measurement_.stamp_ns = timeline.accept();  // on this clock, never before the previous one
    clock_offset_.store(1e-9 * static_cast<double>(timeline.offset()), std::memory_order_relaxed);
    measurement_.receipt_ns = nanosecondsOf(now);
    measurement_.sequence = guard.accepted();
    measurement_.relative_state = relative_state_;
    cycle_->measurement().write(measurement_);
    // The command is in this measurement's axes: its frame names the command's (commandFrame()).
    if (tfFrameName(msg->header.frame_id) != accepted_frame_) {  // only this thread writes it
      accepted_frame_.assign(tfFrameName(msg->header.frame_id));
      const std::lock_guard<std::mutex> lock(reasons_mutex_);
      command_frame_ = accepted_frame_;
    }
    if (on_accepted_) {
      on_accepted_(skipped);
    }
  });
  const std::string& rejection = timeline.guard().lastRejection();
  if (measurement_rejection_ != rejection) {  // only this thread writes it
    const std::lock_guard<std::mutex> lock(reasons_mutex_);
    measurement_rejection_ = rejection;
  }
}

void FollowerInputs::onLeaderBroadcast(const ros::MessageEvent<LeaderBroadcast const>& event) {
  const LeaderBroadcast::ConstPtr& msg = event.getConstMessage();
  InputTimeline& timeline = leader_timeline_;
  admitGuarded(timeline, name_, [&] {
    const ros::Time now = ros::Time::now();
    if (!checkHeader(timeline, msg->header, now, publisherOf(event))) {
      return;
    }
    std::string why;
    Eigen::VectorXd input;
    Eigen::VectorXd disturbance;
    if (!leaderInputFromMsg(*msg, axes_, &input, &disturbance, &why)) {
      timeline.reject(Rejection::kContent, why);
      return;
    }
    leader_.stamp_ns = timeline.accept();  // on this clock (~clock_skew/policy)
    leader_.receipt_ns = nanosecondsOf(now);
    leader_.sequence = timeline.guard().accepted();
    leader_.acceleration = design_.leaderAcceleration(input, disturbance);
    cycle_->leader().write(leader_);
  });
  const std::string& rejection = timeline.guard().lastRejection();
  if (leader_rejection_ != rejection) {  // only this thread writes it
    const std::lock_guard<std::mutex> lock(reasons_mutex_);
    leader_rejection_ = rejection;
  }
}

void FollowerInputs::onOdometry(const ros::MessageEvent<nav_msgs::Odometry const>& event) {
  const nav_msgs::Odometry::ConstPtr& msg = event.getConstMessage();
  InputTimeline& timeline = odometry_timeline_;
  admitGuarded(timeline, name_, [&] {
    const ros::Time now = ros::Time::now();
    if (!checkHeader(timeline, msg->header, now, publisherOf(event))) {
      return;
    }
    // The conventions of ~odometry/pose_frame and ~odometry/twist_frame, as the odometry input
    // reads them; the velocity stays in the axes of the pose's frame (no tf2 here: ~odom_frame
    // can require that frame).
    if (options_.odometry.pose_frame == PoseFrame::kHeader &&
        labelledWithItsOwnFrame(msg->header.frame_id, msg->child_frame_id)) {
      timeline.reject(Rejection::kContent,
                      ownFrameLabelReason(msg->header.frame_id, "~measurement_frame"));
      return;
    }
    const OdometryVerdict verdict =
        originState(toOdometrySample(*msg),
                    options_.odometry.twist_in_body_frame ? TwistFrame::kBody : TwistFrame::kWorld,
                    options_.odometry.quaternion_tolerance, axes_, &origin_state_);
    if (verdict != OdometryVerdict::kAccepted) {
      timeline.reject(Rejection::kContent,
                      verdict == OdometryVerdict::kSelfQuaternionNotUnit
                          ? "an orientation that is not a unit quaternion, which the body-frame "
                            "twist needs (~odometry/twist_frame body)"
                          : "non-finite position, velocity or orientation");
      return;
    }
    odometry_state_ = origin_state_;
    own_state_.controlled_velocity = origin_state_.tail(axes_);
    own_state_.controlled_position = origin_state_.head(axes_);
    const double look_ahead =
        options_.input == MeasurementInput::kOdometry              ? options_.odometry.look_ahead
        : options_.input == MeasurementInput::kRelativeMeasurement ? 0.0
                                                                   : options_.position.look_ahead;
    if ((options_.turning || options_.path) && look_ahead > 0.0) {
      // The look-ahead point, which the relative measurement (~input odometry, tf or position) is
      // taken at.
      const Eigen::Matrix<double, 6, 1> point = bodyPointState(
          toOdometrySample(*msg), Eigen::Vector3d(look_ahead, 0.0, 0.0),
          options_.odometry.twist_in_body_frame ? TwistFrame::kBody : TwistFrame::kWorld);
      if (point.allFinite()) {
        own_state_.controlled_velocity = point.segment(3, axes_);
        own_state_.controlled_position = point.head(axes_);
      }
    }
    own_state_.stamp_ns = timeline.accept();
    own_state_.receipt_ns = nanosecondsOf(now);
    own_state_.sequence = timeline.guard().accepted();
    own_state_.state = odometry_state_;
    cycle_->ownState().write(own_state_);
  });
}

}  // namespace projection_collision_avoidance
