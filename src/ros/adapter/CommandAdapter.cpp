#include "projection_collision_avoidance/ros/CommandAdapter.hpp"

#include <chrono>
#include <utility>

#include <geometry_msgs/Twist.h>
#include <geometry_msgs/TwistStamped.h>
#include <geometry_msgs/Vector3Stamped.h>

#include "projection_collision_avoidance/cycle/FrameNames.hpp"
#include "projection_collision_avoidance/ros/GuardedTransformListener.hpp"
#include "projection_collision_avoidance/ros/MessageConversions.hpp"
#include "projection_collision_avoidance/ros/OdometryFrames.hpp"
#include "projection_collision_avoidance/ros/RosParameters.hpp"

#include "adapter/CommandAdapterOptions.hpp"
#include "adapter/CommandFrame.hpp"

namespace projection_collision_avoidance {
namespace {

/// Below this realised fraction of the commanded velocity change the diagnostics warn.
constexpr double kMinRealisedFraction = 0.8;

/// Steady (monotonic) time in s, the watchdog's clock.
double steadySeconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

std::unique_ptr<CommandAdapterOptions> readOptions(const ros::NodeHandle& private_nh) {
  NodeOptionReader reader(private_nh);
  auto options = std::make_unique<CommandAdapterOptions>(readCommandAdapterOptions(reader));
  reader.echo(private_nh.getNamespace());
  return options;
}

geometry_msgs::Vector3 toVector3Msg(const Eigen::Vector3d& v) {
  geometry_msgs::Vector3 msg;
  msg.x = v.x();
  msg.y = v.y();
  msg.z = v.z();
  return msg;
}

}  // namespace

CommandAdapter::CommandAdapter(ros::NodeHandle nh, ros::NodeHandle private_nh)
    : name_(private_nh.getNamespace()),
      options_(readOptions(private_nh)),
      converter_(options_->converter),
      watchdog_(options_->command_timeout),
      command_timeline_(
          "command", InputGuardLimits{"", options_->max_future_stamp, options_->command_timeout}),
      // A state stream: an odometry older than the latest accepted is superseded.
      odometry_timeline_("odom", InputGuardLimits{"", options_->max_future_stamp, 0.0, true}),
      world_frame_(options_->world_frame),
      base_frame_(options_->base_frame),
      acceleration_(Eigen::VectorXd::Zero(options_->converter.axes)),
      diagnostics_(nh, private_nh, name_) {
  if (options_->accel_enu) {
    accel_publisher_ = nh.advertise<geometry_msgs::Vector3Stamped>("setpoint_accel", 10);
  }
  if (options_->twist || options_->unicycle) {
    twist_publisher_ = nh.advertise<geometry_msgs::Twist>("cmd_vel", 10);
  }
  if (options_->twist_stamped) {
    twist_stamped_publisher_ = nh.advertise<geometry_msgs::TwistStamped>("cmd_vel_stamped", 10);
  }
  tf_listener_ = std::make_unique<GuardedTransformListener>(
      &tf_buffer_, nh, TransformGuardOptions{options_->max_future_stamp}, name_);
  command_frame_ =
      std::make_unique<CommandFrame>(name_, &tf_buffer_, options_->world_frame.empty());
  odometry_subscriber_ = nh.subscribe("odom", 10, &CommandAdapter::onOdometry, this,
                                      ros::TransportHints().tcpNoDelay());
  command_subscriber_ = nh.subscribe("command", 10, &CommandAdapter::onCommand, this,
                                     ros::TransportHints().tcpNoDelay());
  diagnostics_.setHardwareID(name_);
  diagnostics_.add("command adapter", this, &CommandAdapter::diagnose);
  watchdog_timer_ = nh.createSteadyTimer(ros::WallDuration(1.0 / options_->watchdog_rate),
                                         &CommandAdapter::onWatchdog, this);
  ROS_INFO_STREAM(name_ << ": " << (options_->accel_enu ? "setpoint_accel " : "")
                        << (options_->twist ? "cmd_vel (velocity) " : "")
                        << (options_->unicycle ? "cmd_vel (unicycle) " : "")
                        << (options_->twist_stamped ? "cmd_vel_stamped " : "")
                        << "from command, stop after " << options_->command_timeout
                        << " s without one");
}

CommandAdapter::~CommandAdapter() {
  watchdog_timer_.stop();
  command_subscriber_.shutdown();
  odometry_subscriber_.shutdown();
}

void CommandAdapter::onOdometry(const ros::MessageEvent<nav_msgs::Odometry const>& event) {
  const nav_msgs::Odometry::ConstPtr& msg = event.getConstMessage();
  const std::lock_guard<std::mutex> lock(mutex_);
  admitGuarded(odometry_timeline_, name_, [&] {
    const ros::Time now = ros::Time::now();
    if (!checkHeader(odometry_timeline_, msg->header, now, publisherOf(event))) {
      return;
    }
    // The heading in the world frame of the commands (tf2 when the odometry's frame differs).
    OdometrySample sample;
    std::string why;
    if (!odometryInFrame(*msg, options_->world_frame,
                         options_->converter.odometry_twist_frame == TwistFrame::kBody,
                         options_->pose_frame, tf_buffer_, 0.0, "~world_frame", &sample, &why)) {
      odometry_timeline_.reject(Rejection::kContent, why);
      return;
    }
    if (!converter_.observe(sample)) {
      odometry_timeline_.reject(Rejection::kContent,
                                "non-finite field or an orientation that is not a unit quaternion");
      return;
    }
    odometry_timeline_.accept();
    if (options_->base_frame.empty() && !msg->child_frame_id.empty()) {
      base_frame_ = tfFrame(msg->child_frame_id);
    } else if (base_frame_.empty() && options_->twist_stamped && !warned_no_base_frame_) {
      // REP 105 names the twist's frame in child_frame_id; empty, the twist is taken as the
      // body's (~odometry/twist_frame body), whose name only ~base_frame can give.
      warned_no_base_frame_ = true;
      ROS_WARN_STREAM(name_ << ": the odometry's child_frame_id is empty: its twist is taken in "
                               "the body frame, and cmd_vel_stamped in the base frame carries an "
                               "empty frame_id until ~base_frame names it");
    }
    world_frame_ =
        options_->world_frame.empty() ? tfFrame(msg->header.frame_id) : options_->world_frame;
  });
}

void CommandAdapter::onCommand(const ros::MessageEvent<geometry_msgs::AccelStamped const>& event) {
  const geometry_msgs::AccelStamped::ConstPtr& msg = event.getConstMessage();
  const std::lock_guard<std::mutex> lock(mutex_);
  admitGuarded(command_timeline_, name_, [&] {
    const ros::Time now = ros::Time::now();
    if (command_timeline_.noteTime(nanosecondsOf(now))) {  // the timeline restarts
      watchdog_.reset();
    }
    if (!checkHeader(command_timeline_, msg->header, now, publisherOf(event))) {
      return;
    }
    std::string why;
    if (!commandFromAccelMsg(*msg, options_->converter.axes, &acceleration_, &why)) {
      command_timeline_.reject(Rejection::kContent, why);
      return;
    }
    command_timeline_.accept();
    // In the follower's world frame, which its frame_id names: into this node's world frame.
    command_frame_->toWorld(msg->header.frame_id, world_frame_, base_frame_, steadySeconds(),
                            &acceleration_);
    const ConvertedCommand& command = converter_.convert(acceleration_, now.toSec());
    if (!command.heading_known) {
      ROS_WARN_STREAM_THROTTLE(5.0, name_ << ": no fresh own odometry (odom) for the heading: "
                                             "sending the stop");
    }
    watchdog_.commandSent(steadySeconds());
    publish(command, msg->header.stamp);
  });
}

void CommandAdapter::onWatchdog(const ros::SteadyTimerEvent& /*event*/) {
  const std::lock_guard<std::mutex> lock(mutex_);
  diagnostics_.update();
  const WatchdogDecision decision = watchdog_.check(steadySeconds());
  if (!decision.send_stop) {
    return;
  }
  if (decision.stop_began) {
    ROS_WARN_STREAM(name_ << ": no command for " << options_->command_timeout << " s ("
                          << toString(decision.state) << "): sending the stop");
  }
  const ros::Time now = ros::Time::now();
  publish(converter_.stop(now.toSec()), now);
}

void CommandAdapter::diagnose(diagnostic_updater::DiagnosticStatusWrapper& status) {
  // Called from onWatchdog() (diagnostics_.update()) with mutex_ held.
  using diagnostic_msgs::DiagnosticStatus;
  const std::string& command_rejection = command_timeline_.guard().lastRejection();
  const std::string& odometry_rejection = odometry_timeline_.guard().lastRejection();
  status.summary(DiagnosticStatus::OK, "converting commands");
  if (!command_rejection.empty()) {
    status.mergeSummary(DiagnosticStatus::WARN, "rejecting commands: " + command_rejection);
  }
  if (!odometry_rejection.empty()) {
    status.mergeSummary(DiagnosticStatus::WARN, "rejecting odometry: " + odometry_rejection);
  }
  if (!command_frame_->warning().empty()) {
    status.mergeSummary(DiagnosticStatus::WARN, command_frame_->warning());
  }
  const std::int64_t now_ns = nanosecondsOf(ros::Time::now());
  for (const InputTimeline* timeline : {&command_timeline_, &odometry_timeline_}) {
    const std::int64_t heard = timeline->foreignHeard();
    if (heard != InputTimeline::kNone && now_ns >= heard &&
        now_ns - heard <= InputTimeline::kForeignReportNs) {
      status.mergeSummary(DiagnosticStatus::ERROR,
                          "another publisher on " +
                              std::string(timeline == &command_timeline_ ? "command" : "odom") +
                              " (refused: " + timeline->holder() + " holds it)");
    }
  }
  status.add("foreign_commands", command_timeline_.foreignMessages());
  status.add("foreign_odometry", odometry_timeline_.foreignMessages());
  status.add("input_restarts", command_timeline_.restarts() + odometry_timeline_.restarts());
  status.add("command_turned_by_tf", command_frame_->turned());
  status.add("accepted_commands", command_timeline_.guard().accepted());
  status.add("rejected_commands", command_timeline_.rejected());
  status.add("accepted_odometry", odometry_timeline_.guard().accepted());
  status.add("rejected_odometry", odometry_timeline_.rejected());
  status.add("superseded_odometry", odometry_timeline_.superseded());
  status.add("max_future_stamp (s)", options_->max_future_stamp);
  status.add("non_finite_outputs_replaced_by_stop", replaced_outputs_);
  status.add("non_finite_outputs_not_published", unpublished_outputs_);
  if (replaced_outputs_ + unpublished_outputs_ > 0) {
    status.mergeSummary(DiagnosticStatus::WARN,
                        "non-finite conversions (overflowing inputs) replaced by the stop");
  }
  // How the vehicle follows the velocity commands (VehicleResponseEstimator, doc/vehicles.md).
  const VehicleResponse& response = converter_.response();
  status.add("vehicle_update_interval (s)", response.update_interval);
  status.add("vehicle_response_delay (s)", converter_.delay());
  status.add("vehicle_realised_fraction", response.realised_fraction);
  if (options_->twist || options_->twist_stamped || options_->unicycle) {
    if (response.realised_fraction < kMinRealisedFraction) {
      status.mergeSummary(
          DiagnosticStatus::WARN,
          "the vehicle realises " + std::to_string(response.realised_fraction) +
              " of the commanded velocity change: a lagging velocity loop (~velocity/lag) or a "
              "limit below the command");
    }
  }
}

void CommandAdapter::publish(const ConvertedCommand& command, const ros::Time& stamp) {
  if (command.replaced_non_finite) {
    ++replaced_outputs_;
    ROS_WARN_STREAM_THROTTLE(5.0, name_ << ": a command converted into non-finite values (an "
                                           "overflow of huge inputs): sending the stop instead");
  }
  if (!isFinite(command)) {  // the converter never gives one: nothing leaves unchecked
    ++unpublished_outputs_;
    ROS_ERROR_STREAM_THROTTLE(5.0, name_ << ": a non-finite command not published");
    return;
  }
  if (options_->accel_enu) {
    geometry_msgs::Vector3Stamped accel;
    accel.header.stamp = stamp;
    accel.header.frame_id = world_frame_;
    accel.vector = toVector3Msg(command.acceleration);
    accel_publisher_.publish(accel);
  }
  geometry_msgs::Twist twist;
  if (options_->unicycle) {
    twist.linear.x = command.unicycle.velocity.v;
    twist.angular.z = command.unicycle.velocity.omega;
  } else {
    twist.linear = toVector3Msg(command.velocity);
  }
  if (options_->twist || options_->unicycle) {
    twist_publisher_.publish(twist);
  }
  if (options_->twist_stamped) {
    geometry_msgs::TwistStamped stamped;
    stamped.header.stamp = stamp;
    stamped.header.frame_id = options_->unicycle || options_->converter.velocity_in_base_frame
                                  ? base_frame_
                                  : world_frame_;
    stamped.twist = twist;
    twist_stamped_publisher_.publish(stamped);
  }
}

}  // namespace projection_collision_avoidance
