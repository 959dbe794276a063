#include "follower/FollowerInputs.hpp"

#include <utility>

#include "projection_collision_avoidance/ros/MessageConversions.hpp"

namespace projection_collision_avoidance {

FollowerInputs::FollowerInputs(ros::NodeHandle nh, std::string node_name,
                               const FollowerNodeOptions& options, const ControllerDesign& design,
                               FollowerCycle* cycle, StepSink on_step)
    : name_(std::move(node_name)),
      options_(options),
      design_(design),
      axes_(design.parameters.model.double_integrator_axes),
      cycle_(cycle),
      on_step_(std::move(on_step)),
      // A message older than its timeout on arrival could only be stale: refused as such.
      measurement_guard_("relative_measurement", {options.measurement_frame,
                                                  options.max_future_stamp,
                                                  options.measurement_timeout}),
      leader_guard_("leader_broadcast", {options.leader_broadcast_frame, options.max_future_stamp,
                                         options.leader_timeout}) {
  measurement_.relative_state.setZero(2 * axes_);
  leader_.acceleration.setZero(axes_);
  relative_state_ = Eigen::VectorXd::Zero(2 * axes_);
  measurement_subscriber_ = nh.subscribe("relative_measurement", 10, &FollowerInputs::onMeasurement,
                                         this, ros::TransportHints().tcpNoDelay());
  leader_subscriber_ = nh.subscribe("leader_broadcast", 10, &FollowerInputs::onLeaderBroadcast, this);
}

FollowerInputStats FollowerInputs::stats() const {
  FollowerInputStats stats;
  stats.rejected_measurements = rejected_measurements_.load(std::memory_order_relaxed);
  stats.rejected_leader_broadcasts = rejected_leader_broadcasts_.load(std::memory_order_relaxed);
  const std::lock_guard<std::mutex> lock(reasons_mutex_);
  stats.measurement_rejection = measurement_rejection_;
  stats.leader_rejection = leader_rejection_;
  return stats;
}

bool FollowerInputs::admitHeader(InputGuard& guard, ClockWatch& clock,
                                 const std_msgs::Header& header, const ros::Time& now) {
  if (clock.wentBack(now)) {
    guard.restartTimeline();  // the control cycle notes and reports the jump itself
  }
  return checkHeader(guard, header, now);
}

void FollowerInputs::onMeasurement(const RelativeMeasurement::ConstPtr& msg) {
  const std::int64_t previous_stamp = measurement_guard_.lastStamp();
  const bool had_one = measurement_guard_.haveAccepted();
  bool accepted = false;
  admitGuarded(measurement_guard_, name_, [&] {
    const ros::Time now = ros::Time::now();
    if (!admitHeader(measurement_guard_, measurement_clock_, msg->header, now)) {
      return;
    }
    std::string why;
    if (!relativeStateFromMsg(*msg, axes_, &relative_state_, &why)) {
      measurement_guard_.reject(Rejection::kContent, why);
      return;
    }
    const std::int64_t stamp = nanosecondsOf(msg->header.stamp);
    measurement_guard_.accept(stamp, nanosecondsOf(now));
    measurement_.stamp_ns = stamp;
    measurement_.receipt_ns = nanosecondsOf(now);
    measurement_.sequence = measurement_guard_.accepted();
    measurement_.relative_state = relative_state_;
    cycle_->measurement().write(measurement_);
    accepted = true;
    if (options_.trigger == ControlTrigger::kMeasurement) {
      const std::uint32_t skipped =
          had_one ? skippedPeriods(1e-9 * static_cast<double>(stamp - previous_stamp),
                                   design_.period)
                  : 0;
      cycle_->stepOnMeasurement(nanosecondsOf(now), skipped, &trigger_output_);
      on_step_(trigger_output_);
    }
  });
  rejected_measurements_.store(measurement_guard_.rejected(), std::memory_order_relaxed);
  if (!accepted || !measurement_rejection_.empty()) {
    const std::lock_guard<std::mutex> lock(reasons_mutex_);
    measurement_rejection_ = measurement_guard_.lastRejection();
  }
}

void FollowerInputs::onLeaderBroadcast(const LeaderBroadcast::ConstPtr& msg) {
  bool accepted = false;
  admitGuarded(leader_guard_, name_, [&] {
    const ros::Time now = ros::Time::now();
    if (!admitHeader(leader_guard_, leader_clock_, msg->header, now)) {
      return;
    }
    std::string why;
    Eigen::VectorXd input;
    Eigen::VectorXd disturbance;
    if (!leaderInputFromMsg(*msg, axes_, &input, &disturbance, &why)) {
      leader_guard_.reject(Rejection::kContent, why);
      return;
    }
    const std::int64_t stamp = nanosecondsOf(msg->header.stamp);
    leader_guard_.accept(stamp, nanosecondsOf(now));
    leader_.stamp_ns = stamp;
    leader_.receipt_ns = nanosecondsOf(now);
    leader_.sequence = leader_guard_.accepted();
    leader_.acceleration = design_.leaderAcceleration(input, disturbance);
    cycle_->leader().write(leader_);
    accepted = true;
  });
  rejected_leader_broadcasts_.store(leader_guard_.rejected(), std::memory_order_relaxed);
  if (!accepted || !leader_rejection_.empty()) {
    const std::lock_guard<std::mutex> lock(reasons_mutex_);
    leader_rejection_ = leader_guard_.lastRejection();
  }
}

}  // namespace projection_collision_avoidance
