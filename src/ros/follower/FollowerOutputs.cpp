#include "follower/FollowerOutputs.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <utility>

#include <boost/make_shared.hpp>
#include <geometry_msgs/AccelStamped.h>
#include <visualization_msgs/MarkerArray.h>

#include "projection_collision_avoidance/FollowerStatus.h"
#include "projection_collision_avoidance/LeaderBroadcast.h"
#include "projection_collision_avoidance/ros/InputAdmission.hpp"
#include "projection_collision_avoidance/ros/MessageConversions.hpp"

#include "follower/StatusMessage.hpp"

namespace projection_collision_avoidance {

FollowerOutputs::FollowerOutputs(ros::NodeHandle nh, ros::NodeHandle private_nh,
                                 std::string node_name, const FollowerNodeOptions& options,
                                 double control_rate, const FormationMember& member,
                                 const Eigen::VectorXd& separation, const FollowerInputs* inputs)
    : name_(std::move(node_name)),
      options_(options),
      member_(member),
      separation_(separation),
      inputs_(inputs),
      diagnostics_(nh, private_nh, private_nh.getNamespace()) {
  command_publisher_.advertise<geometry_msgs::AccelStamped>(nh, "command", 10);
  broadcast_publisher_.advertise<LeaderBroadcast>(nh, "broadcast", 10);
  status_publisher_.advertise<FollowerStatus>(nh, "status", 10);
  marker_publisher_.advertise<visualization_msgs::MarkerArray>(nh, "markers", 2);
  diagnostics_.setHardwareID(options_.follower_frame);
  diagnostics_.add("follower controller", this, &FollowerOutputs::diagnose);
  // Markers every control_rate / marker_rate steps, statuses every control_rate / status_rate.
  const auto stepsPer = [control_rate](double rate) -> std::uint64_t {
    return rate > 0.0 ? static_cast<std::uint64_t>(std::max(1L, std::lround(control_rate / rate)))
                      : 0;
  };
  steps_per_marker_ = stepsPer(options_.marker_rate);
  steps_per_status_ = stepsPer(options_.status_rate);
}

FollowerOutputs::~FollowerOutputs() { stopThread(); }

void FollowerOutputs::remember(const FollowerCycleOutput& out) {
  if (out.stepped) {
    latest_ = out;
    return;
  }
  latest_.now_ns = out.now_ns;
  latest_.steps = out.steps;
  latest_.mode = out.mode;
  latest_.xi_max = out.xi_max;
  latest_.xi_soft = out.xi_soft;
  latest_.perimeter = out.perimeter;
  latest_.acceleration_limit = out.acceleration_limit;
  latest_.jerk_limit = out.jerk_limit;
  latest_.tracker_enabled = out.tracker_enabled;
  latest_.time_headway = out.time_headway;
  latest_.missed_periods = out.missed_periods;
  latest_.late_periods = out.late_periods;
  latest_.held_measurements = out.held_measurements;
  latest_.tick_delay = out.tick_delay;
  latest_.time_jumps = out.time_jumps;
  latest_.time_jump = out.time_jump;
  latest_.stall = out.stall;
}

void FollowerOutputs::publish(const FollowerCycleOutput& out) {
  const std::lock_guard<std::mutex> lock(publish_mutex_);
  logEvents(out);
  remember(out);
  if (out.stepped) {
    const ros::Time stamp = rosTimeOf(out.stamp_ns);
    // Published as shared pointers: a subscriber in the same process (a nodelet) gets the
    // message itself, neither serialised nor copied. Its frame_id is the world frame the
    // command is expressed in (that of the measurements), else, none known, the follower's.
    inputs_->commandFrame(&command_frame_);
    command_publisher_.publish(boost::make_shared<geometry_msgs::AccelStamped>(
        toAccelMsg(out.status.command, stamp,
                   command_frame_.empty() ? options_.follower_frame : command_frame_)));
    // The other messages are made only while someone subscribes to them.
    if (broadcast_publisher_.subscribed()) {
      auto broadcast = boost::make_shared<LeaderBroadcast>();  // its acceleration, no state
      broadcast->header.stamp = stamp;
      broadcast->header.frame_id = options_.follower_frame;
      broadcast->input = toStdVector(out.status.command);
      broadcast_publisher_.publish(broadcast);
    }
    // Every so many steps, and at every change of mode (a fallback is never left out).
    if (steps_per_status_ > 0 &&
        ((out.steps - 1) % steps_per_status_ == 0 || out.mode != status_mode_)) {
      if (status_publisher_.subscribed()) {
        status_publisher_.publish(boost::make_shared<FollowerStatus>(
            toStatusMsg(out, inputs_->stats(out.now_ns), member_, options_.follower_frame)));
      }
      status_mode_ = out.mode;
    }
    if (steps_per_marker_ > 0 && (out.steps - 1) % steps_per_marker_ == 0 &&
        marker_publisher_.subscribed()) {
      publishMarkers(out);
    }
  }
  diagnostics_.update();
}

void FollowerOutputs::describeTrackerGain(const Eigen::MatrixXd& gain) {
  std::ostringstream text;  // G_e in force, row by row
  text << gain.format(
      Eigen::IOFormat(Eigen::StreamPrecision, Eigen::DontAlignCols, ", ", "; ", "", "", "[", "]"));
  const std::lock_guard<std::mutex> lock(gain_mutex_);
  tracker_gain_ = text.str();
}

void FollowerOutputs::startThread(std::function<void()> idle) {
  stop_ = false;
  thread_ = std::thread([this, idle = std::move(idle)] { run(idle); });
}

void FollowerOutputs::stopThread() {
  if (!thread_.joinable()) {
    return;
  }
  stop_ = true;
  handoff_.wake();
  thread_.join();
}

void FollowerOutputs::run(const std::function<void()>& idle) {
  constexpr std::int64_t kIdleNs = 100000000;  // 100 ms
  FollowerCycleOutput out;
  std::uint32_t seen = handoff_.count();
  while (true) {
    while (handoff_.pop(&out)) {
      try {
        publish(out);
      } catch (const std::exception& error) {  // as a tick of the timer loop would report it
        ROS_ERROR_STREAM_THROTTLE(5.0, name_ << ": control tick failed: " << error.what());
      }
    }
    if (idle) {
      idle();
    }
    if (stop_) {
      return;
    }
    seen = handoff_.wait(seen, kIdleNs);
  }
}

void FollowerOutputs::logEvents(const FollowerCycleOutput& out) {
  if (out.time_jump < 0.0) {
    ROS_WARN_STREAM(name_ << ": ROS time went back by " << -out.time_jump << " s, to "
                          << rosTimeOf(out.now_ns).toSec()
                          << " s: the inputs of the old timeline are forgotten; braking until "
                             "fresh measurements arrive");
  }
  if (out.stall > 0.0) {
    ROS_WARN_STREAM_THROTTLE(5.0, name_ << ": control tick " << out.stall
                                        << " s late (the process was stalled): waiting up to "
                                        << 0.5 * options_.measurement_timeout
                                        << " s for the input sent meanwhile");
  }
  if (out.mode == logged_mode_) {
    return;
  }
  logged_mode_ = out.mode;
  switch (out.mode) {
    case FollowerMode::kTracking:
      ROS_INFO_STREAM(name_ << ": tracking");
      break;
    case FollowerMode::kLeaderLost:
      ROS_WARN_STREAM(name_ << ": leader broadcast older than ~leader_timeout ("
                            << options_.leader_timeout
                            << " s): running on the relative measurement alone");
      break;
    case FollowerMode::kMeasurementLost:
      ROS_ERROR_STREAM(name_ << ": relative measurement older than ~measurement_timeout ("
                             << options_.measurement_timeout
                             << " s): braking relative to the leader until it returns");
      break;
    case FollowerMode::kWaiting:
      break;
  }
}

void FollowerOutputs::diagnose(diagnostic_updater::DiagnosticStatusWrapper& status) {
  // Called from publish() (diagnostics_.update()) with publish_mutex_ held.
  using diagnostic_msgs::DiagnosticStatus;
  const FollowerCycleOutput& s = latest_;
  const FollowerInputStats inputs = inputs_->stats(nanosecondsOf(ros::Time::now()));
  switch (s.mode) {
    case FollowerMode::kWaiting:
      status.summary(DiagnosticStatus::ERROR, "no relative measurement yet");
      break;
    case FollowerMode::kMeasurementLost:
      status.summary(DiagnosticStatus::ERROR, "relative measurement lost: braking fallback");
      break;
    case FollowerMode::kLeaderLost:
      status.summary(DiagnosticStatus::WARN, "leader broadcast lost: running without u_1");
      break;
    case FollowerMode::kTracking:
      status.summary(DiagnosticStatus::OK, "tracking");
      break;
  }
  const double xi_norm = s.xi.norm();
  if (s.mode != FollowerMode::kWaiting && xi_norm > s.xi_max) {
    status.mergeSummary(DiagnosticStatus::ERROR, "relative error outside xi_max");
  }
  if (!inputs.measurement_rejection.empty()) {
    status.mergeSummary(DiagnosticStatus::WARN,
                        "rejecting measurements: " + inputs.measurement_rejection);
  }
  if (!inputs.leader_rejection.empty()) {
    status.mergeSummary(DiagnosticStatus::WARN,
                        "rejecting leader broadcasts: " + inputs.leader_rejection);
  }
  const std::int64_t now_ns = nanosecondsOf(ros::Time::now());
  if (inputs.foreign_heard_ns != InputTimeline::kNone && now_ns >= inputs.foreign_heard_ns &&
      now_ns - inputs.foreign_heard_ns <= InputTimeline::kForeignReportNs) {
    status.mergeSummary(DiagnosticStatus::ERROR, "another publisher on an input (" +
                                                     std::to_string(inputs.foreign_messages) +
                                                     " messages refused)");
  }
  const NeighbourReport& neighbours = s.neighbours;
  if (neighbours.configured && s.mode != FollowerMode::kWaiting && !neighbours.fresh) {
    status.mergeSummary(DiagnosticStatus::ERROR, "neighbour array stale: braking fallback");
  }
  if (neighbours.configured && std::isinf(neighbours.smallest_barrier) &&
      neighbours.smallest_barrier < 0.0) {
    status.mergeSummary(DiagnosticStatus::ERROR, "inside a neighbour's perimeter");
  }
  if (s.barriers.given && s.barriers.infeasible) {
    status.mergeSummary(DiagnosticStatus::WARN,
                        "barrier filter infeasible: the acceleration limit cannot meet a barrier");
  }
  if (!inputs.neighbour_rejection.empty()) {
    status.mergeSummary(DiagnosticStatus::WARN,
                        "rejecting neighbour arrays: " + inputs.neighbour_rejection);
  }
  status.add("mode", toString(s.mode));
  status.add("xi_norm (m)", xi_norm);
  status.add("xi_max (m)", s.xi_max);
  status.add("margin (m)", s.xi_max - xi_norm);
  status.add("estimate_norm (m)", s.status.estimate_norm);
  status.add("projection_active", s.status.projection_active);
  status.add("command_saturated", s.status.command_saturated);
  status.add("acceleration_limit (m/s^2)", s.acceleration_limit);
  status.add("command_rate_limited", s.status.command_rate_limited);
  status.add("jerk_limit (m/s^3)", s.jerk_limit);
  status.add("tracker_enabled", s.tracker_enabled);
  {
    const std::lock_guard<std::mutex> lock(gain_mutex_);
    status.add("tracker_gain", tracker_gain_);
  }
  status.add("rejected_measurements", inputs.rejected_measurements);
  status.add("rejected_leader_broadcasts", inputs.rejected_leader_broadcasts);
  status.add("time_headway (s)", s.time_headway);
  status.add("own_state_fresh", s.own_state_fresh);
  status.add("rejected_odometry", inputs.rejected_odometry);
  status.add("superseded_odometry", inputs.superseded_odometry);
  status.add("input", toString(options_.input));
  status.add("rejected_input_messages", inputs.rejected_input);
  status.add("superseded_input_messages", inputs.superseded_input);
  status.add("input_skew (s)", inputs.input_skew);
  status.add("measurement_age (s)", inputs.measurement_age);
  status.add("measurement_skew (s)", inputs.measurement_skew);
  status.add("leader_skew (s)", inputs.leader_skew);
  status.add("clock_offset (s)", inputs.clock_offset);
  status.add("clock_skew_policy", toString(options_.clock_skew.policy));
  status.add("leader_age (s)", inputs.leader_age);
  status.add("foreign_messages", inputs.foreign_messages);
  status.add("input_restarts", inputs.input_restarts);
  status.add("input_handovers", inputs.input_handovers);
  status.add("time_jumps", s.time_jumps);
  status.add("trigger", toString(options_.trigger));
  status.add("control_loop", toString(options_.control_loop));
  status.add("transport", toString(options_.transport));
  status.add("control_priority", options_.control_priority);
  status.add("lock_memory", options_.lock_memory);
  status.add("ticks", s.steps);
  status.add("missed_periods", s.missed_periods);
  status.add("late_periods", s.late_periods);
  status.add("held_measurements", s.held_measurements);
  status.add("tick_delay (s)", s.tick_delay);
  if (neighbours.configured) {
    status.add("neighbours_age (s)", inputs.neighbours_age);
    status.add("rejected_neighbours", inputs.rejected_neighbours);
    status.add("neighbours_sensed", neighbours.sensed);
    status.add("neighbour_constraints", neighbours.kept);
    status.add("neighbour_constraints_active", neighbours.active);
    status.add("neighbour_constraints_dropped", neighbours.dropped);
    status.add("nearest_neighbour (m)", neighbours.nearest);
    status.add("neighbour_barrier (m/s)", neighbours.smallest_barrier);
    status.add("binding_neighbour", std::string(neighbours.binding_id.data()));
  }
  const BarrierReport& barriers = s.barriers;
  if (barriers.configured) {
    status.add("barriers", barriers.barriers);
    status.add("barriers_active", barriers.active);
    status.add("barriers_dropped", barriers.dropped);
    status.add("barrier_infeasible", barriers.infeasible ? "true" : "false");
    status.add("target_barrier (m^2)", barriers.target_barrier);
    status.add("binding_barrier", std::string(barriers.binding_id.data()));
  }
}

}  // namespace projection_collision_avoidance
