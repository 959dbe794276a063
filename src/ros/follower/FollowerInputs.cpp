#include "follower/FollowerInputs.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

#include "projection_collision_avoidance/ros/MessageConversions.hpp"

namespace projection_collision_avoidance {

FollowerInputs::FollowerInputs(std::string node_name, const FollowerNodeOptions& options,
                               const ControllerDesign& design, FollowerCycle* cycle,
                               StepSink on_step)
    : name_(std::move(node_name)),
      options_(options),
      design_(design),
      axes_(design.parameters.model.double_integrator_axes),
      cycle_(cycle),
      on_step_(std::move(on_step)),
      // A message older than its timeout on arrival could only be stale: refused as such.
      measurement_guard_(
          "relative_measurement",
          {options.measurement_frame, options.max_future_stamp, options.measurement_timeout}),
      measurement_correction_(options.clock_skew),
      leader_guard_("leader_broadcast", {options.leader_broadcast_frame, options.max_future_stamp,
                                         options.leader_timeout}),
      leader_correction_(options.clock_skew),
      odometry_guard_("odom",
                      {options.odom_frame, options.max_future_stamp, options.measurement_timeout}) {
  measurement_.relative_state.setZero(2 * axes_);
  leader_.acceleration.setZero(axes_);
  own_state_.state.setZero(2 * axes_);
  relative_state_ = Eigen::VectorXd::Zero(2 * axes_);
  odometry_state_ = Eigen::VectorXd::Zero(2 * axes_);
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
  if (design_.parameters.time_headway > 0.0) {
    odometry_subscriber_ = nh.subscribe("odom", 10, &FollowerInputs::onOdometry, this,
                                        ros::TransportHints().tcpNoDelay());
  }
}

void FollowerInputs::Heard::note(std::int64_t stamp_ns, std::int64_t now_ns) {
  receipt_ns.store(now_ns, std::memory_order_relaxed);
  effective_ns.store(std::min(stamp_ns, now_ns), std::memory_order_relaxed);
}

double FollowerInputs::Heard::ageAt(std::int64_t now_ns) const {
  const std::int64_t effective = effective_ns.load(std::memory_order_relaxed);
  if (effective == kNone || receipt_ns.load(std::memory_order_relaxed) > now_ns) {
    return -1.0;
  }
  return 1e-9 * static_cast<double>(now_ns - effective);
}

FollowerInputStats FollowerInputs::stats(std::int64_t now_ns) const {
  FollowerInputStats stats;
  stats.measurement_age = measurement_heard_.ageAt(now_ns);
  stats.leader_age = leader_heard_.ageAt(now_ns);
  stats.rejected_measurements = rejected_measurements_.load(std::memory_order_relaxed);
  stats.rejected_leader_broadcasts = rejected_leader_broadcasts_.load(std::memory_order_relaxed);
  stats.rejected_odometry = rejected_odometry_.load(std::memory_order_relaxed);
  stats.measurement_skew = measurement_skew_.load(std::memory_order_relaxed);
  stats.leader_skew = leader_skew_.load(std::memory_order_relaxed);
  stats.clock_offset = clock_offset_.load(std::memory_order_relaxed);
  if (const MeasurementAdapter* adapter = adapter_.load(std::memory_order_acquire)) {
    stats.rejected_input = adapter->rejected();
    const double skew = adapter->skew();
    stats.input_skew = std::isfinite(skew) ? skew : -1.0;
  }
  const std::lock_guard<std::mutex> lock(reasons_mutex_);
  stats.measurement_rejection = measurement_rejection_;
  stats.leader_rejection = leader_rejection_;
  return stats;
}

bool FollowerInputs::admitHeader(InputGuard& guard, ClockWatch& clock, Heard& heard,
                                 StampCorrection& correction, const std_msgs::Header& header,
                                 const ros::Time& now, std::int64_t* offset_ns) {
  if (clock.wentBack(now)) {
    guard.restartTimeline();  // the control cycle notes and reports the jump itself
    heard.effective_ns.store(Heard::kNone, std::memory_order_relaxed);
    correction.reset();
  }
  const std::int64_t now_ns = nanosecondsOf(now);
  *offset_ns = correction.offsetFor(nanosecondsOf(header.stamp), now_ns);
  return guard.checkHeader(header.frame_id, nanosecondsOf(header.stamp), now_ns - *offset_ns);
}

void FollowerInputs::onMeasurement(const RelativeMeasurement::ConstPtr& msg) {
  admitMeasurement(*msg);
}

void FollowerInputs::admitMeasurement(const RelativeMeasurement& measurement) {
  const RelativeMeasurement* msg = &measurement;
  admitGuarded(measurement_guard_, name_, [&] {
    const ros::Time now = ros::Time::now();
    std::int64_t offset = 0;
    if (!admitHeader(measurement_guard_, measurement_clock_, measurement_heard_,
                     measurement_correction_, msg->header, now, &offset)) {
      if (measurement_guard_.lastKind() == Rejection::kFuture) {
        cycle_->noteFutureMeasurement();  // this clock may still be catching up after a stall
      }
      return;
    }
    std::string why;
    if (!relativeStateFromMsg(*msg, axes_, &relative_state_, &why)) {
      measurement_guard_.reject(Rejection::kContent, why);
      return;
    }
    const std::int64_t raw = nanosecondsOf(msg->header.stamp);
    const std::int64_t now_ns = nanosecondsOf(now);
    // Measurement trigger: the periods between this stamp and the last accepted one's.
    const std::uint32_t skipped =
        measurement_guard_.haveAccepted()
            ? skippedPeriods(1e-9 * static_cast<double>(raw - measurement_guard_.lastStamp()),
                             design_.period)
            : 0;
    // On this clock (~clock_skew/policy), never before the previous one.
    const bool first = !measurement_guard_.haveAccepted();
    const std::int64_t stamp =
        first ? raw + offset : std::max(raw + offset, last_corrected_ns_ + 1);
    last_corrected_ns_ = stamp;
    measurement_guard_.accept(raw, now_ns - offset);
    measurement_correction_.accepted(raw, now_ns);
    measurement_skew_.store(measurement_correction_.lastSkew(), std::memory_order_relaxed);
    clock_offset_.store(1e-9 * static_cast<double>(offset), std::memory_order_relaxed);
    measurement_heard_.note(stamp, now_ns);
    measurement_.stamp_ns = stamp;
    measurement_.receipt_ns = nanosecondsOf(now);
    measurement_.sequence = measurement_guard_.accepted();
    measurement_.relative_state = relative_state_;
    cycle_->measurement().write(measurement_);
    if (options_.trigger == ControlTrigger::kMeasurement) {
      // ROS time read again once the other inputs are latched (their callbacks may run on other
      // threads): none of them counts as received after the step's time.
      cycle_->stepOnMeasurement([] { return nanosecondsOf(ros::Time::now()); }, skipped,
                                &trigger_output_);
      on_step_(trigger_output_);
    }
  });
  rejected_measurements_.store(measurement_guard_.rejected(), std::memory_order_relaxed);
  if (measurement_rejection_ != measurement_guard_.lastRejection()) {  // only this thread writes it
    const std::lock_guard<std::mutex> lock(reasons_mutex_);
    measurement_rejection_ = measurement_guard_.lastRejection();
  }
}

void FollowerInputs::onLeaderBroadcast(const LeaderBroadcast::ConstPtr& msg) {
  admitGuarded(leader_guard_, name_, [&] {
    const ros::Time now = ros::Time::now();
    std::int64_t offset = 0;
    if (!admitHeader(leader_guard_, leader_clock_, leader_heard_, leader_correction_, msg->header,
                     now, &offset)) {
      return;
    }
    std::string why;
    Eigen::VectorXd input;
    Eigen::VectorXd disturbance;
    if (!leaderInputFromMsg(*msg, axes_, &input, &disturbance, &why)) {
      leader_guard_.reject(Rejection::kContent, why);
      return;
    }
    const std::int64_t raw = nanosecondsOf(msg->header.stamp);
    const std::int64_t stamp = raw + offset;  // on this clock (~clock_skew/policy)
    leader_guard_.accept(raw, nanosecondsOf(now) - offset);
    leader_correction_.accepted(raw, nanosecondsOf(now));
    leader_skew_.store(leader_correction_.lastSkew(), std::memory_order_relaxed);
    leader_heard_.note(stamp, nanosecondsOf(now));
    leader_.stamp_ns = stamp;
    leader_.receipt_ns = nanosecondsOf(now);
    leader_.sequence = leader_guard_.accepted();
    leader_.acceleration = design_.leaderAcceleration(input, disturbance);
    cycle_->leader().write(leader_);
  });
  rejected_leader_broadcasts_.store(leader_guard_.rejected(), std::memory_order_relaxed);
  if (leader_rejection_ != leader_guard_.lastRejection()) {  // only this thread writes it
    const std::lock_guard<std::mutex> lock(reasons_mutex_);
    leader_rejection_ = leader_guard_.lastRejection();
  }
}

void FollowerInputs::onOdometry(const nav_msgs::Odometry::ConstPtr& msg) {
  admitGuarded(odometry_guard_, name_, [&] {
    const ros::Time now = ros::Time::now();
    if (!checkHeaderOnTimeline(odometry_guard_, odometry_clock_, msg->header, now)) {
      return;
    }
    if (!stateFromOdometryMsg(*msg, axes_, &odometry_state_)) {
      odometry_guard_.reject(Rejection::kContent, "non-finite position or velocity");
      return;
    }
    const std::int64_t stamp = nanosecondsOf(msg->header.stamp);
    odometry_guard_.accept(stamp, nanosecondsOf(now));
    own_state_.stamp_ns = stamp;
    own_state_.receipt_ns = nanosecondsOf(now);
    own_state_.sequence = odometry_guard_.accepted();
    own_state_.state = odometry_state_;
    cycle_->ownState().write(own_state_);
  });
  rejected_odometry_.store(odometry_guard_.rejected(), std::memory_order_relaxed);
}

}  // namespace projection_collision_avoidance
