#include "projection_collision_avoidance/ros/FollowerNode.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <iomanip>
#include <limits>
#include <sstream>
#include <system_error>

#include <geometry_msgs/AccelStamped.h>
#include <visualization_msgs/MarkerArray.h>

#include "projection_collision_avoidance/ControllerDesign.hpp"
#include "projection_collision_avoidance/FollowerStatus.h"
#include "projection_collision_avoidance/ParameterError.hpp"
#include "projection_collision_avoidance/ros/MessageConversions.hpp"
#include "projection_collision_avoidance/ros/RosParameters.hpp"

namespace projection_collision_avoidance {
namespace {

/// Member ~formation_index of the scenario's formation.
FormationMember memberOf(NodeOptionReader& reader, const Scenario& scenario) {
  const int index = reader.integer("formation_index", 1, 1, FormationSpec::kMaxFollowers);
  if (index > scenario.formation.followers) {
    throw ParameterError("~formation_index",
                         "is " + std::to_string(index) + " but the formation has " +
                             std::to_string(scenario.formation.followers) + " follower(s)");
  }
  const std::vector<FormationMember> members =
      layoutFormation(scenario.formation, scenario.controller.separation,
                      scenario.leader_initial_state, scenario.follower_initial_state);
  return members[static_cast<std::size_t>(index - 1)];
}

/// Control periods skipped between two consecutive due times @p gap s apart: none up to 1.5
/// periods, else round(gap / period) - 1.
std::uint32_t skippedPeriods(double gap, double period) {
  if (!(gap > 1.5 * period)) {
    return 0;
  }
  const double skipped = std::round(gap / period) - 1.0;
  return skipped >= static_cast<double>(std::numeric_limits<std::uint32_t>::max())
             ? std::numeric_limits<std::uint32_t>::max()
             : static_cast<std::uint32_t>(skipped);
}

/// Adds without wrapping around.
void addSaturated(std::uint32_t* counter, std::uint32_t amount) {
  *counter = *counter > std::numeric_limits<std::uint32_t>::max() - amount
                 ? std::numeric_limits<std::uint32_t>::max()
                 : *counter + amount;
}

ControlTrigger triggerOf(const std::string& value) {
  if (value == "timer") {
    return ControlTrigger::kTimer;
  }
  if (value == "measurement") {
    return ControlTrigger::kMeasurement;
  }
  throw ParameterError("~trigger", "must be \"timer\" or \"measurement\", got \"" + value + "\"");
}

/// ~control_loop; "thread" is refused on simulated time (@p sim_time).
ControlLoop controlLoopOf(const std::string& value, bool sim_time) {
  if (value == "timer") {
    return ControlLoop::kTimer;
  }
  if (value == "thread") {
    if (sim_time) {
      throw ParameterError("~control_loop",
                           "\"thread\" sleeps on the monotonic clock and cannot follow simulated "
                           "time (/use_sim_time is true): use \"timer\"");
    }
    return ControlLoop::kThread;
  }
  throw ParameterError("~control_loop", "must be \"timer\" or \"thread\", got \"" + value + "\"");
}

/// The node's options; @p sim_time: whether ROS time is simulated (/use_sim_time).
FollowerNodeOptions readOptions(NodeOptionReader& reader, const ControllerParameters& p,
                                const FormationMember& member, bool sim_time) {
  FollowerNodeOptions options;
  options.formation_index = member.index;
  const double period = 1.0 / p.control_rate;
  options.measurement_timeout =
      reader.number("measurement_timeout", options.measurement_timeout, period, 3600.0);
  options.leader_timeout = reader.number("leader_timeout", options.leader_timeout, period, 3600.0);
  options.max_future_stamp =
      reader.number("max_future_stamp", options.max_future_stamp, 0.0, 3600.0);
  options.use_leader_broadcast = reader.boolean("use_leader_broadcast", false);
  options.measurement_frame = reader.text("measurement_frame", "");
  options.leader_broadcast_frame = reader.text("leader_broadcast_frame", "");
  options.odom_frame = reader.text("odom_frame", "");
  options.follower_frame = reader.text("follower_frame", member.name);
  if (options.follower_frame.empty()) {
    throw ParameterError("~follower_frame", "must not be empty");
  }
  options.marker_rate = reader.number("marker_rate", options.marker_rate, 0.0, p.control_rate);
  options.trigger = triggerOf(reader.text("trigger", toString(options.trigger)));
  options.control_loop =
      controlLoopOf(reader.text("control_loop", toString(options.control_loop)), sim_time);
  options.control_priority =
      reader.integer("control_priority", options.control_priority, 0, kMaxControlPriority);
  if (options.control_priority > 0 && options.control_loop != ControlLoop::kThread) {
    throw ParameterError("~control_priority",
                         "is " + std::to_string(options.control_priority) +
                             " but only the \"thread\" control loop has a priority: set "
                             "~control_loop to \"thread\", or this to 0");
  }
  options.lock_memory = reader.boolean("lock_memory", options.lock_memory);
  return options;
}

}  // namespace

const char* toString(ControlTrigger trigger) {
  return trigger == ControlTrigger::kMeasurement ? "measurement" : "timer";
}

const char* toString(ControlLoop loop) { return loop == ControlLoop::kThread ? "thread" : "timer"; }

FollowerNode::FollowerNode(ros::NodeHandle nh, ros::NodeHandle private_nh)
    : FollowerNode(nh, private_nh, loadDoubleIntegratorScenario(private_nh)) {}

FollowerNode::FollowerNode(ros::NodeHandle nh, ros::NodeHandle private_nh, const Scenario& scenario)
    : nh_(nh),
      private_nh_(private_nh),
      reader_(private_nh),
      member_(memberOf(reader_, scenario)),
      file_parameters_(memberParameters(scenario.controller, member_)),
      parameters_(file_parameters_),
      controller_(ControllerDesign::create(parameters_)),
      axes_(parameters_.model.double_integrator_axes),
      diagnostics_(nh, private_nh),
      reconfigure_server_(reconfigure_mutex_, private_nh) {
  NodeOptionReader& reader = reader_;
  options_ = readOptions(reader, parameters_, member_, ros::Time::isSimTime());
  if (options_.lock_memory) {
    try {
      lockProcessMemory();
    } catch (const std::system_error& error) {
      throw ParameterError(
          "~lock_memory",
          "is true but mlockall(MCL_CURRENT | MCL_FUTURE) failed: " + error.code().message() +
              " (needs root or CAP_IPC_LOCK, or an RLIMIT_MEMLOCK above the "
              "process's size)");
    }
  }
  // A message older than its timeout on arrival could only be stale: refused as such.
  measurement_guard_ = InputGuard(
      "relative_measurement",
      {options_.measurement_frame, options_.max_future_stamp, options_.measurement_timeout});
  leader_guard_ = InputGuard(
      "leader_broadcast",
      {options_.leader_broadcast_frame, options_.max_future_stamp, options_.leader_timeout});
  own_state_guard_ = InputGuard(
      "odom", {options_.odom_frame, options_.max_future_stamp, options_.measurement_timeout});
  const std::string name = private_nh_.getNamespace();
  echoScenario(name, private_nh);
  reader.echo(name);

  period_ = 1.0 / parameters_.control_rate;
  relative_state_ = Eigen::VectorXd::Zero(2 * axes_);
  leader_input_ = Eigen::VectorXd::Zero(axes_);
  own_state_ = Eigen::VectorXd::Zero(2 * axes_);
  command_publisher_ = nh_.advertise<geometry_msgs::AccelStamped>("command", 10);
  broadcast_publisher_ = nh_.advertise<LeaderBroadcast>("broadcast", 10);
  status_publisher_ = nh_.advertise<FollowerStatus>("status", 10);
  marker_publisher_ = nh_.advertise<visualization_msgs::MarkerArray>("markers", 2);
  measurement_subscriber_ = nh_.subscribe("relative_measurement", 10, &FollowerNode::onMeasurement,
                                          this, ros::TransportHints().tcpNoDelay());
  leader_subscriber_ =
      nh_.subscribe("leader_broadcast", 10, &FollowerNode::onLeaderBroadcast, this);
  if (parameters_.time_headway > 0.0) {
    odometry_subscriber_ = nh_.subscribe("odom", 10, &FollowerNode::onOdometry, this,
                                         ros::TransportHints().tcpNoDelay());
  }

  diagnostics_.setHardwareID(options_.follower_frame);
  diagnostics_.add("follower controller", this, &FollowerNode::diagnose);
  applied_config_ = configOf(parameters_);
  reconfigure_server_.updateConfig(applied_config_);
  reconfigure_server_.setCallback(
      [this](FollowerConfig& config, uint32_t level) { onReconfigure(config, level); });

  std::ostringstream loop;
  if (options_.control_loop == ControlLoop::kThread) {
    const int priority = options_.control_priority;
    try {
      control_thread_.start(std::chrono::nanoseconds(std::llround(1e9 / parameters_.control_rate)),
                            priority, [this](const PeriodicTick& tick) { onLoopTick(tick); });
    } catch (const PriorityRefused& error) {
      throw ParameterError("~control_priority",
                           "SCHED_FIFO priority " + std::to_string(priority) +
                               " refused: pthread_setschedparam failed: " + error.code().message() +
                               " (needs root or CAP_SYS_NICE, or an RLIMIT_RTPRIO of at least " +
                               std::to_string(priority) + "; 0 runs without real-time priority)");
    }
    loop << ", control loop: thread"
         << (priority > 0 ? ", SCHED_FIFO " + std::to_string(priority) : std::string());
  } else {
    ros::TimerOptions timer_options(
        ros::Duration(1.0 / parameters_.control_rate),
        [this](const ros::TimerEvent& event) { onControlTick(event); }, &control_queue_);
    timer_ = nh_.createTimer(timer_options);
    control_spinner_ = std::make_unique<ros::AsyncSpinner>(1, &control_queue_);
    control_spinner_->start();
  }
  if (options_.lock_memory) {
    loop << ", memory locked";
  }
  ROS_INFO_STREAM(name << ": " << member_.name << " looking at " << member_.target_name << ", d = ["
                       << parameters_.separation.transpose() << "], running at "
                       << parameters_.control_rate << " Hz (trigger: " << toString(options_.trigger)
                       << loop.str() << "), " << axes_ << " axes, xi_max "
                       << controller_.design().xi_max << " m"
                       << (parameters_.time_headway > 0.0
                               ? ", time headway " + std::to_string(parameters_.time_headway) +
                                     " s from " + odometry_subscriber_.getTopic()
                               : std::string()));
}

FollowerNode::~FollowerNode() {
  control_thread_.stop();  // "thread": ends within one period (at most 10 ms) and a tick
  timer_.stop();
  if (control_spinner_) {
    control_spinner_->stop();
  }
}

void FollowerNode::onMeasurement(const RelativeMeasurement::ConstPtr& msg) {
  const std::lock_guard<std::mutex> lock(mutex_);
  admitGuarded(measurement_guard_, private_nh_.getNamespace(), [&] {
    const ros::Time now = ros::Time::now();
    if (!admitHeader(measurement_guard_, msg->header, now)) {
      return;
    }
    std::string why;
    if (!relativeStateFromMsg(*msg, axes_, &relative_state_, &why)) {
      measurement_guard_.reject(Rejection::kContent, why);
      return;
    }
    const bool triggered = options_.trigger == ControlTrigger::kMeasurement;
    if (triggered && measurement_guard_.haveAccepted()) {
      const double gap = 1e-9 * static_cast<double>(nanosecondsOf(msg->header.stamp) -
                                                    measurement_guard_.lastStamp());
      addSaturated(&missed_periods_, skippedPeriods(gap, period_));
    }
    measurement_guard_.accept(nanosecondsOf(msg->header.stamp), nanosecondsOf(now));
    if (triggered) {
      controlStep(msg->header.stamp, secondsBetween(now, msg->header.stamp));
    }
  });
}

void FollowerNode::onLeaderBroadcast(const LeaderBroadcast::ConstPtr& msg) {
  const std::lock_guard<std::mutex> lock(mutex_);
  admitGuarded(leader_guard_, private_nh_.getNamespace(), [&] {
    const ros::Time now = ros::Time::now();
    if (!admitHeader(leader_guard_, msg->header, now)) {
      return;
    }
    std::string why;
    Eigen::VectorXd input;
    Eigen::VectorXd disturbance;
    if (!leaderInputFromMsg(*msg, axes_, &input, &disturbance, &why)) {
      leader_guard_.reject(Rejection::kContent, why);
      return;
    }
    leader_input_ = controller_.design().leaderAcceleration(input, disturbance);
    leader_guard_.accept(nanosecondsOf(msg->header.stamp), nanosecondsOf(now));
  });
}

void FollowerNode::onOdometry(const nav_msgs::Odometry::ConstPtr& msg) {
  const std::lock_guard<std::mutex> lock(mutex_);
  admitGuarded(own_state_guard_, private_nh_.getNamespace(), [&] {
    const ros::Time now = ros::Time::now();
    if (!admitHeader(own_state_guard_, msg->header, now)) {
      return;
    }
    if (!stateFromOdometryMsg(*msg, axes_, &own_state_)) {
      own_state_guard_.reject(Rejection::kContent, "non-finite position or velocity");
      return;
    }
    own_state_guard_.accept(nanosecondsOf(msg->header.stamp), nanosecondsOf(now));
  });
}

bool FollowerNode::admitHeader(InputGuard& guard, const std_msgs::Header& header,
                               const ros::Time& now) {
  if (clock_.wentBack(now)) {
    onTimeJump(now);
  }
  return checkHeader(guard, header, now);
}

void FollowerNode::onTimeJump(const ros::Time& now) {
  ROS_WARN_STREAM(private_nh_.getNamespace()
                  << ": ROS time went back by " << -clock_.jump() << " s, to " << now.toSec()
                  << " s: the inputs of the old timeline are forgotten; braking until fresh "
                     "measurements arrive");
  measurement_guard_.restartTimeline();
  leader_guard_.restartTimeline();
  own_state_guard_.restartTimeline();
  have_last_expected_ = false;
}

void FollowerNode::logModeChange(FollowerMode mode) {
  const std::string name = private_nh_.getNamespace();
  switch (mode) {
    case FollowerMode::kTracking:
      ROS_INFO_STREAM(name << ": tracking");
      break;
    case FollowerMode::kLeaderLost:
      ROS_WARN_STREAM(name << ": leader broadcast older than ~leader_timeout ("
                           << options_.leader_timeout
                           << " s): running on the relative measurement alone");
      break;
    case FollowerMode::kMeasurementLost:
      ROS_ERROR_STREAM(name << ": relative measurement older than ~measurement_timeout ("
                            << options_.measurement_timeout
                            << " s): braking relative to the leader until it returns");
      break;
    case FollowerMode::kWaiting:
      break;
  }
}

FollowerMode FollowerNode::modeAt(const ros::Time& now, FollowerInputAges* ages) const {
  // After a jump back of ROS time an input heard before has no age on the new timeline
  // (+infinity): stale, so the follower brakes rather than waits.
  ages->have_measurement = measurement_guard_.everAccepted();
  ages->measurement_age = measurement_guard_.ageAt(nanosecondsOf(now));
  ages->have_leader = leader_guard_.everAccepted();
  ages->leader_age = leader_guard_.ageAt(nanosecondsOf(now));
  return selectFollowerMode(
      *ages, FollowerTimeouts{options_.measurement_timeout, options_.leader_timeout});
}

void FollowerNode::onControlTick(const ros::TimerEvent& event) {
  const std::lock_guard<std::mutex> lock(mutex_);
  try {
    const ros::Time now = ros::Time::now();
    if (clock_.wentBack(now)) {
      onTimeJump(now);
    }
    const double delay = secondsBetween(event.current_real, event.current_expected);
    std::uint32_t skipped = 0;
    if (options_.trigger == ControlTrigger::kTimer) {
      if (have_last_expected_) {
        skipped = skippedPeriods(secondsBetween(event.current_expected, last_expected_), period_);
      }
      last_expected_ = event.current_expected;
      have_last_expected_ = true;
    }
    controlTick(now, delay, skipped);
  } catch (const std::exception& error) {
    ROS_ERROR_STREAM_THROTTLE(5.0, private_nh_.getNamespace()
                                       << ": control tick failed: " << error.what());
  }
}

void FollowerNode::onLoopTick(const PeriodicTick& tick) {
  if (!ros::ok()) {  // shutting down: the timer's spinner would not call it either
    return;
  }
  const std::lock_guard<std::mutex> lock(mutex_);
  try {
    const ros::Time now = ros::Time::now();
    if (clock_.wentBack(now)) {
      onTimeJump(now);
    }
    const double delay = 1e-9 * static_cast<double>(tick.actual - tick.expected);
    const std::uint64_t most = std::numeric_limits<std::uint32_t>::max();
    controlTick(now, delay, static_cast<std::uint32_t>(std::min(tick.skipped, most)));
  } catch (const std::exception& error) {
    ROS_ERROR_STREAM_THROTTLE(5.0, private_nh_.getNamespace()
                                       << ": control tick failed: " << error.what());
  }
}

void FollowerNode::controlTick(const ros::Time& now, double delay, std::uint32_t skipped) {
  const double grace = 0.5 * options_.measurement_timeout;
  if (delay > grace) {
    // The tick itself ran late by a good part of the timeout: the process was stalled, and the
    // measurements sent meanwhile are not read yet. Judging their age now would brake for
    // nothing: wait for them (at most `grace` s) before deciding.
    resuming_ = true;
    resumed_at_ = now;
    accepted_at_stall_ = measurement_guard_.accepted();
    ROS_WARN_STREAM_THROTTLE(5.0, private_nh_.getNamespace()
                                      << ": control tick " << delay
                                      << " s late (the process was stalled): waiting up to "
                                      << grace << " s for the input sent meanwhile");
  }
  if (resuming_) {
    if (measurement_guard_.accepted() == accepted_at_stall_ &&
        secondsBetween(now, resumed_at_) < grace) {
      addSaturated(&missed_periods_, skipped + 1);
      diagnostics_.update();
      return;
    }
    resuming_ = false;
  }
  if (options_.trigger == ControlTrigger::kTimer) {
    addSaturated(&missed_periods_, skipped);
    controlStep(now, delay);
    return;
  }
  // Measurement-triggered: the measurements run the steps while they are fresh; the timer only
  // brakes once they are stale, and keeps the diagnostics going.
  FollowerInputAges ages;
  if (modeAt(now, &ages) == FollowerMode::kMeasurementLost) {
    controlStep(now, delay);
  } else {
    diagnostics_.update();
  }
}

void FollowerNode::controlStep(const ros::Time& stamp, double delay) {
  FollowerInputAges ages;
  const FollowerMode mode = modeAt(stamp, &ages);
  if (mode != mode_) {
    logModeChange(mode);
    mode_ = mode;
  }
  if (mode == FollowerMode::kWaiting) {
    diagnostics_.update();
    return;
  }
  const std::uint64_t tick = ticks_++;
  tick_delay_ = delay;
  if (delay > 0.5 * period_) {
    addSaturated(&late_periods_, 1);
  }
  leader_fresh_ = ages.have_leader && ages.leader_age <= options_.leader_timeout;
  const bool use_leader_input = options_.use_leader_broadcast && leader_fresh_;
  const Eigen::VectorXd xi = relative_state_ - parameters_.separation;
  // The time headway (S1) acts from the own odometry while it is fresh; without it the tick runs
  // the paper's constant spacing.
  own_state_fresh_ = parameters_.time_headway > 0.0 && own_state_guard_.everAccepted() &&
                     own_state_guard_.ageAt(nanosecondsOf(stamp)) <= options_.measurement_timeout;
  const RuntimeFollowerStatus* status = nullptr;
  if (mode == FollowerMode::kMeasurementLost) {
    status =
        use_leader_input ? &controller_.stepFallback(leader_input_) : &controller_.stepFallback();
  } else {
    const Eigen::VectorXd y = parameters_.model.C * xi;
    if (own_state_fresh_) {
      status = use_leader_input ? &controller_.stepWithOwnState(y, own_state_, leader_input_)
                                : &controller_.stepWithOwnState(y, own_state_);
    } else {
      status = use_leader_input ? &controller_.step(y, leader_input_) : &controller_.step(y);
    }
  }
  command_publisher_.publish(toAccelMsg(status->command, stamp, options_.follower_frame));
  LeaderBroadcast broadcast;  // for a follower behind this one: its acceleration, no state
  broadcast.header.stamp = stamp;
  broadcast.header.frame_id = options_.follower_frame;
  broadcast.input = toStdVector(status->command);
  broadcast_publisher_.publish(broadcast);
  last_xi_norm_ = xi.norm();
  publishStatus(stamp, xi, ages);
  const std::uint64_t ticks_per_marker =
      options_.marker_rate > 0.0
          ? static_cast<std::uint64_t>(
                std::max(1L, std::lround(parameters_.control_rate / options_.marker_rate)))
          : 0;
  if (ticks_per_marker > 0 && tick % ticks_per_marker == 0) {
    publishMarkers(stamp, xi);
  }
  diagnostics_.update();
}

void FollowerNode::publishStatus(const ros::Time& now, const Eigen::VectorXd& xi,
                                 const FollowerInputAges& ages) {
  const RuntimeFollowerStatus& s = controller_.status();
  const ControllerDesign& design = controller_.design();
  FollowerStatus msg;
  msg.header.stamp = now;
  msg.header.frame_id = options_.follower_frame;
  msg.formation_index = static_cast<uint32_t>(member_.index);
  msg.target = member_.target_name;
  msg.mode = static_cast<uint8_t>(mode_);
  msg.mode_name = toString(mode_);
  msg.fallback = s.fallback;
  msg.measurement_fresh = mode_ == FollowerMode::kTracking || mode_ == FollowerMode::kLeaderLost;
  msg.measurement_age = ages.measurement_age;
  msg.rejected_measurements = measurement_guard_.rejected();
  msg.leader_fresh = leader_fresh_;
  msg.leader_age = ages.have_leader ? ages.leader_age : std::numeric_limits<double>::infinity();
  msg.rejected_leader_broadcasts = leader_guard_.rejected();
  msg.xi = toStdVector(xi);
  msg.xi_hat = toStdVector(s.estimate);
  msg.xi_norm = xi.norm();
  msg.xi_hat_norm = s.estimate_norm;
  msg.xi_max = design.xi_max;
  msg.xi_soft = design.xi_soft;
  msg.margin = design.xi_max - msg.xi_norm;
  msg.constraint = s.constraint_value;
  msg.projection_active = s.projection_active;
  msg.command_saturated = s.command_saturated;
  msg.acceleration_limit = parameters_.acceleration_limit;
  msg.command_rate_limited = s.command_rate_limited;
  msg.jerk_limit = parameters_.jerk_limit;
  msg.tracker_enabled = parameters_.tracker_enabled;
  msg.command = toStdVector(s.command);
  msg.baseline_command = toStdVector(s.baseline_command);
  msg.tracker_command = toStdVector(s.tracker_command);
  msg.feedforward_command = toStdVector(s.feedforward_command);
  msg.headway_command = toStdVector(s.headway_command);
  msg.own_state_fresh = own_state_fresh_;
  msg.fallback_command = toStdVector(s.fallback_command);
  msg.separation = relative_state_.head(axes_).norm();
  msg.perimeter = design.perimeter;
  msg.ticks = ticks_;
  msg.missed_periods = missed_periods_;
  msg.late_periods = late_periods_;
  msg.tick_delay = tick_delay_;
  msg.time_jumps = clock_.jumps();
  status_publisher_.publish(msg);
}

void FollowerNode::publishMarkers(const ros::Time& now, const Eigen::VectorXd& xi) {
  using visualization_msgs::Marker;
  const ControllerDesign& design = controller_.design();
  const RuntimeFollowerStatus& s = controller_.status();
  const std::string& frame = options_.follower_frame;
  const double separation = relative_state_.head(axes_).norm();
  const bool inside_perimeter = separation < design.perimeter;
  visualization_msgs::MarkerArray markers;
  // Safety perimeter alpha ||d|| around the follower: green, red once the leader is inside.
  // A flat disc on the ground plane (a sphere in 3-D), so the markers above it stay visible.
  visualization_msgs::Marker perimeter =
      toMarker(frame, now, "perimeter", member_.index, Marker::SPHERE, Eigen::Vector3d::Zero(),
               2.0 * design.perimeter,
               {inside_perimeter ? 1.0F : 0.1F, inside_perimeter ? 0.1F : 0.8F, 0.1F, 0.35F});
  if (axes_ < 3) {
    perimeter.type = Marker::CYLINDER;
    perimeter.scale.z = 0.02;
  }
  markers.markers.push_back(perimeter);
  // The slot x_1 - d, relative to the follower: (p_1 - p_2) - d_p.
  const Eigen::VectorXd slot = relative_state_.head(axes_) - parameters_.separation.head(axes_);
  visualization_msgs::Marker slot_marker = toMarker(frame, now, "slot", member_.index, Marker::CUBE,
                                                    toVector3(slot), 0.3, {0.8F, 0.8F, 0.8F, 0.9F});
  markers.markers.push_back(slot_marker);
  // The follower where the CF estimate puts it: p_2 + (xi - xi_hat)_p. Grey in the fallback,
  // where xi is the last measured one and xi_hat a prediction.
  const bool fallback = mode_ == FollowerMode::kMeasurementLost;
  const Eigen::VectorXd ghost = (xi - s.estimate).head(axes_);
  const MarkerColor ghost_color =
      fallback ? MarkerColor{0.5F, 0.5F, 0.5F, 0.45F} : MarkerColor{1.0F, 0.55F, 0.0F, 0.45F};
  markers.markers.push_back(toMarker(frame, now, "cf_estimate", member_.index, Marker::SPHERE,
                                     toVector3(ghost), 0.5, ghost_color));
  // ||xi|| against xi_max, as text above the follower; the mode unless tracking.
  const float shade = xi.norm() > design.xi_max || fallback ? 0.2F : 1.0F;  // red: trouble
  visualization_msgs::Marker text =
      toMarker(frame, now, "bound", member_.index, Marker::TEXT_VIEW_FACING,
               Eigen::Vector3d(0.0, 0.0, 1.2), 0.35, {1.0F, shade, shade, 1.0F});
  std::ostringstream label;
  label << std::fixed << std::setprecision(2) << "|xi| " << xi.norm() << " / xi_max "
        << design.xi_max << " m";
  if (fallback) {
    label << "\nMEASUREMENT LOST: braking";
  } else if (mode_ == FollowerMode::kLeaderLost) {
    label << "\nleader broadcast lost";
  }
  text.text = label.str();
  markers.markers.push_back(text);
  marker_publisher_.publish(markers);
}

void FollowerNode::diagnose(diagnostic_updater::DiagnosticStatusWrapper& status) {
  // Called from a control step or tick with mutex_ held.
  using diagnostic_msgs::DiagnosticStatus;
  const ControllerDesign& design = controller_.design();
  const RuntimeFollowerStatus& s = controller_.status();
  switch (mode_) {
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
  if (mode_ != FollowerMode::kWaiting && last_xi_norm_ > design.xi_max) {
    status.mergeSummary(DiagnosticStatus::ERROR, "relative error outside xi_max");
  }
  if (!measurement_guard_.lastRejection().empty()) {
    status.mergeSummary(DiagnosticStatus::WARN,
                        "rejecting measurements: " + measurement_guard_.lastRejection());
  }
  if (!leader_guard_.lastRejection().empty()) {
    status.mergeSummary(DiagnosticStatus::WARN,
                        "rejecting leader broadcasts: " + leader_guard_.lastRejection());
  }
  status.add("mode", toString(mode_));
  status.add("xi_norm (m)", last_xi_norm_);
  status.add("xi_max (m)", design.xi_max);
  status.add("margin (m)", design.xi_max - last_xi_norm_);
  status.add("estimate_norm (m)", s.estimate_norm);
  status.add("projection_active", s.projection_active);
  status.add("command_saturated", s.command_saturated);
  status.add("acceleration_limit (m/s^2)", parameters_.acceleration_limit);
  status.add("command_rate_limited", s.command_rate_limited);
  status.add("jerk_limit (m/s^3)", parameters_.jerk_limit);
  status.add("tracker_enabled", parameters_.tracker_enabled);
  std::ostringstream gain;  // G_e in force, row by row
  gain << parameters_.tracker_gain.format(
      Eigen::IOFormat(Eigen::StreamPrecision, Eigen::DontAlignCols, ", ", "; ", "", "", "[", "]"));
  status.add("tracker_gain", gain.str());
  status.add("rejected_measurements", measurement_guard_.rejected());
  status.add("rejected_leader_broadcasts", leader_guard_.rejected());
  status.add("time_headway (s)", parameters_.time_headway);
  status.add("own_state_fresh", own_state_fresh_);
  status.add("rejected_odometry", own_state_guard_.rejected());
  const std::int64_t now_ns = nanosecondsOf(ros::Time::now());
  status.add("measurement_age (s)",
             measurement_guard_.haveAccepted() ? measurement_guard_.ageAt(now_ns) : -1.0);
  status.add("leader_age (s)", leader_guard_.haveAccepted() ? leader_guard_.ageAt(now_ns) : -1.0);
  status.add("time_jumps", clock_.jumps());
  status.add("trigger", toString(options_.trigger));
  status.add("control_loop", toString(options_.control_loop));
  status.add("control_priority", options_.control_priority);
  status.add("lock_memory", options_.lock_memory);
  status.add("ticks", ticks_);
  status.add("missed_periods", missed_periods_);
  status.add("late_periods", late_periods_);
  status.add("tick_delay (s)", tick_delay_);
}

FollowerConfig FollowerNode::configOf(const ControllerParameters& parameters) const {
  FollowerConfig config;
  config.tracker_enabled = parameters.tracker_enabled;
  config.alpha = parameters.alpha;
  config.epsilon = parameters.epsilon;
  config.tracker_natural_frequency = 0.0;  // 0 keeps the configured G_e matrix
  config.tracker_damping = 0.7;
  return config;
}

void FollowerNode::onReconfigure(FollowerConfig& config, uint32_t /*level*/) {
  const std::lock_guard<std::mutex> lock(mutex_);
  ControllerParameters candidate = parameters_;
  candidate.tracker_enabled = config.tracker_enabled;
  candidate.alpha = config.alpha;
  candidate.epsilon = config.epsilon;
  try {
    for (const auto& [name, value] :
         {std::pair<const char*, double>{"alpha", config.alpha},
          {"epsilon", config.epsilon},
          {"tracker_natural_frequency", config.tracker_natural_frequency},
          {"tracker_damping", config.tracker_damping}}) {
      if (!std::isfinite(value)) {
        throw ParameterError(name, "must be finite, got " + std::to_string(value));
      }
    }
    if (config.tracker_natural_frequency < 0.0) {
      throw ParameterError("tracker_natural_frequency",
                           "must be >= 0 (0: the scenario's gain), got " +
                               std::to_string(config.tracker_natural_frequency));
    }
    if (config.tracker_natural_frequency > 0.0) {
      if (!candidate.model.C.isIdentity(0.0)) {
        throw ParameterError("tracker_natural_frequency", "needs C = identity");
      }
      candidate.tracker_gain = doubleIntegratorGain(
          Eigen::VectorXd::Constant(axes_, config.tracker_natural_frequency),
          Eigen::VectorXd::Constant(axes_, config.tracker_damping), "tracker_natural_frequency");
    } else {
      candidate.tracker_gain = file_parameters_.tracker_gain;  // 0: the scenario file's gain
    }
    controller_.setDesign(ControllerDesign::create(candidate));
    parameters_ = candidate;
    ROS_INFO_STREAM(
        private_nh_.getNamespace()
        << ": reconfigured: tracker " << (candidate.tracker_enabled ? "on" : "off") << ", alpha "
        << candidate.alpha << ", epsilon " << candidate.epsilon << ", tracker gain "
        << (config.tracker_natural_frequency > 0.0 ? "from the frequency" : "of the scenario file")
        << ", xi_max " << controller_.design().xi_max << " m");
    applied_config_ = config;
  } catch (const ParameterError& error) {
    ROS_ERROR_STREAM(private_nh_.getNamespace()
                     << ": reconfiguration refused, previous values kept: " << error.what());
    config = applied_config_;
  }
}

}  // namespace projection_collision_avoidance
