#include "projection_collision_avoidance/ros/FollowerNode.hpp"

#include <cmath>
#include <iomanip>
#include <sstream>

#include <geometry_msgs/AccelStamped.h>
#include <visualization_msgs/MarkerArray.h>

#include "projection_collision_avoidance/ControllerDesign.hpp"
#include "projection_collision_avoidance/FollowerStatus.h"
#include "projection_collision_avoidance/ParameterError.hpp"
#include "projection_collision_avoidance/ros/MessageConversions.hpp"
#include "projection_collision_avoidance/ros/RosParameters.hpp"

namespace projection_collision_avoidance {
namespace {

FollowerNodeOptions readOptions(NodeOptionReader& reader, const ControllerParameters& p) {
  FollowerNodeOptions options;
  const double period = 1.0 / p.control_rate;
  options.measurement_timeout =
      reader.number("measurement_timeout", options.measurement_timeout, period, 3600.0);
  options.leader_timeout = reader.number("leader_timeout", options.leader_timeout, period, 3600.0);
  options.max_future_stamp =
      reader.number("max_future_stamp", options.max_future_stamp, 0.0, 3600.0);
  options.use_leader_broadcast = reader.boolean("use_leader_broadcast", false);
  options.measurement_frame = reader.text("measurement_frame", "");
  options.follower_frame = reader.text("follower_frame", options.follower_frame);
  options.marker_rate = reader.number("marker_rate", options.marker_rate, 0.0, p.control_rate);
  return options;
}

visualization_msgs::Marker sphereMarker(const std::string& frame, const ros::Time& stamp,
                                        const std::string& ns, int id,
                                        const Eigen::Vector3d& position, double diameter, float r,
                                        float g, float b, float a) {
  visualization_msgs::Marker marker;
  marker.header.frame_id = frame;
  marker.header.stamp = stamp;
  marker.ns = ns;
  marker.id = id;
  marker.type = visualization_msgs::Marker::SPHERE;
  marker.action = visualization_msgs::Marker::ADD;
  marker.pose.position.x = position.x();
  marker.pose.position.y = position.y();
  marker.pose.position.z = position.z();
  marker.pose.orientation.w = 1.0;
  marker.frame_locked = true;  // follows the follower's tf frame between marker updates
  marker.scale.x = marker.scale.y = marker.scale.z = diameter;
  marker.color.r = r;
  marker.color.g = g;
  marker.color.b = b;
  marker.color.a = a;
  return marker;
}

}  // namespace

FollowerNode::FollowerNode(ros::NodeHandle nh, ros::NodeHandle private_nh)
    : nh_(nh),
      private_nh_(private_nh),
      parameters_(loadDoubleIntegratorScenario(private_nh).controller),
      controller_(ControllerDesign::create(parameters_)),
      axes_(parameters_.model.double_integrator_axes),
      diagnostics_(nh, private_nh),
      reconfigure_server_(reconfigure_mutex_, private_nh) {
  NodeOptionReader reader(private_nh);
  options_ = readOptions(reader, parameters_);
  const std::string name = ros::this_node::getName();
  echoScenario(name, private_nh);
  reader.echo(name);

  relative_state_ = Eigen::VectorXd::Zero(2 * axes_);
  leader_input_ = Eigen::VectorXd::Zero(axes_);
  command_publisher_ = nh_.advertise<geometry_msgs::AccelStamped>("command", 10);
  status_publisher_ = nh_.advertise<FollowerStatus>("status", 10);
  marker_publisher_ = nh_.advertise<visualization_msgs::MarkerArray>("markers", 2);
  measurement_subscriber_ = nh_.subscribe("relative_measurement", 10, &FollowerNode::onMeasurement,
                                          this, ros::TransportHints().tcpNoDelay());
  if (options_.use_leader_broadcast) {
    leader_subscriber_ =
        nh_.subscribe("leader_broadcast", 10, &FollowerNode::onLeaderBroadcast, this);
  }

  diagnostics_.setHardwareID(options_.follower_frame);
  diagnostics_.add("follower controller", this, &FollowerNode::diagnose);
  applied_config_ = configOf(parameters_);
  reconfigure_server_.updateConfig(applied_config_);
  reconfigure_server_.setCallback(
      [this](FollowerConfig& config, uint32_t level) { onReconfigure(config, level); });

  timer_ = nh_.createTimer(ros::Duration(1.0 / parameters_.control_rate),
                           &FollowerNode::onControlTick, this);
  ROS_INFO_STREAM(name << ": running at " << parameters_.control_rate << " Hz, " << axes_
                       << " axes, xi_max " << controller_.design().xi_max << " m");
}

void FollowerNode::rejectMeasurement(const std::string& why) {
  ++rejected_measurements_;
  if (why != last_rejection_) {
    ROS_WARN_STREAM(ros::this_node::getName() << ": measurement rejected: " << why);
    last_rejection_ = why;
  } else {
    ROS_WARN_STREAM_THROTTLE(5.0, ros::this_node::getName()
                                      << ": measurements rejected (" << rejected_measurements_
                                      << " so far): " << why);
  }
}

void FollowerNode::onMeasurement(const RelativeMeasurement::ConstPtr& msg) {
  const std::lock_guard<std::mutex> lock(mutex_);
  std::string why;
  Eigen::VectorXd state;
  if (!relativeStateFromMsg(*msg, axes_, &state, &why)) {
    rejectMeasurement(why);
    return;
  }
  if (!options_.measurement_frame.empty() && msg->header.frame_id != options_.measurement_frame) {
    rejectMeasurement("frame_id '" + msg->header.frame_id + "', expected '" +
                      options_.measurement_frame + "'");
    return;
  }
  if (msg->header.stamp > ros::Time::now() + ros::Duration(options_.max_future_stamp)) {
    rejectMeasurement("stamped in the future");
    return;
  }
  if (have_measurement_ && msg->header.stamp < measurement_stamp_) {
    rejectMeasurement("stamped before the last accepted measurement");
    return;
  }
  relative_state_ = state;
  measurement_stamp_ = msg->header.stamp;
  have_measurement_ = true;
  last_rejection_.clear();
}

void FollowerNode::onLeaderBroadcast(const LeaderBroadcast::ConstPtr& msg) {
  const std::lock_guard<std::mutex> lock(mutex_);
  const Eigen::VectorXd input = toEigen(msg->input);
  if (input.size() != axes_ || !input.allFinite()) {
    ROS_WARN_STREAM_THROTTLE(5.0, ros::this_node::getName()
                                      << ": leader broadcast ignored: input must have " << axes_
                                      << " finite entries");
    return;
  }
  leader_input_ = input;
  leader_stamp_ = msg->header.stamp;
  have_leader_input_ = true;
}

void FollowerNode::onControlTick(const ros::TimerEvent& /*event*/) {
  const std::lock_guard<std::mutex> lock(mutex_);
  const ros::Time now = ros::Time::now();
  if (!have_measurement_) {
    diagnostics_.update();
    return;
  }
  const bool fresh = (now - measurement_stamp_).toSec() <= options_.measurement_timeout;
  const Eigen::VectorXd xi = relative_state_ - parameters_.separation;
  const Eigen::VectorXd y = parameters_.model.C * xi;
  const bool leader_fresh = options_.use_leader_broadcast && have_leader_input_ &&
                            (now - leader_stamp_).toSec() <= options_.leader_timeout;
  const RuntimeFollowerStatus& status =
      leader_fresh ? controller_.step(y, leader_input_) : controller_.step(y);
  command_publisher_.publish(toAccelMsg(status.command, now, options_.follower_frame));
  last_tick_fresh_ = fresh;
  last_xi_norm_ = xi.norm();
  publishStatus(now, xi, fresh);
  const long ticks_per_marker =
      options_.marker_rate > 0.0
          ? std::max(1L, std::lround(parameters_.control_rate / options_.marker_rate))
          : 0;
  if (ticks_per_marker > 0 && ticks_ % ticks_per_marker == 0) {
    publishMarkers(now, xi);
  }
  ++ticks_;
  diagnostics_.update();
}

void FollowerNode::publishStatus(const ros::Time& now, const Eigen::VectorXd& xi, bool fresh) {
  const RuntimeFollowerStatus& s = controller_.status();
  const ControllerDesign& design = controller_.design();
  FollowerStatus msg;
  msg.header.stamp = now;
  msg.header.frame_id = options_.follower_frame;
  msg.measurement_fresh = fresh;
  msg.rejected_measurements = rejected_measurements_;
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
  msg.tracker_enabled = parameters_.tracker_enabled;
  msg.command = toStdVector(s.command);
  msg.baseline_command = toStdVector(s.baseline_command);
  msg.tracker_command = toStdVector(s.tracker_command);
  msg.feedforward_command = toStdVector(s.feedforward_command);
  msg.separation = relative_state_.head(axes_).norm();
  msg.perimeter = design.perimeter;
  status_publisher_.publish(msg);
}

void FollowerNode::publishMarkers(const ros::Time& now, const Eigen::VectorXd& xi) {
  const ControllerDesign& design = controller_.design();
  const RuntimeFollowerStatus& s = controller_.status();
  const std::string& frame = options_.follower_frame;
  const double separation = relative_state_.head(axes_).norm();
  const bool inside_perimeter = separation < design.perimeter;
  visualization_msgs::MarkerArray markers;
  // Safety perimeter alpha ||d|| around the follower: green, red once the leader is inside.
  // A flat disc on the ground plane (a sphere in 3-D), so the markers above it stay visible.
  visualization_msgs::Marker perimeter =
      sphereMarker(frame, now, "perimeter", 0, Eigen::Vector3d::Zero(), 2.0 * design.perimeter,
                   inside_perimeter ? 1.0F : 0.1F, inside_perimeter ? 0.1F : 0.8F, 0.1F, 0.35F);
  if (axes_ < 3) {
    perimeter.type = visualization_msgs::Marker::CYLINDER;
    perimeter.scale.z = 0.02;
  }
  markers.markers.push_back(perimeter);
  // The slot x_1 - d, relative to the follower: (p_1 - p_2) - d_p.
  const Eigen::VectorXd slot = relative_state_.head(axes_) - parameters_.separation.head(axes_);
  visualization_msgs::Marker slot_marker =
      sphereMarker(frame, now, "slot", 0, toVector3(slot), 0.3, 0.8F, 0.8F, 0.8F, 0.9F);
  slot_marker.type = visualization_msgs::Marker::CUBE;
  markers.markers.push_back(slot_marker);
  // The follower where the CF estimate puts it: p_2 + (xi - xi_hat)_p.
  const Eigen::VectorXd ghost = (xi - s.estimate).head(axes_);
  markers.markers.push_back(
      sphereMarker(frame, now, "cf_estimate", 0, toVector3(ghost), 0.5, 1.0F, 0.55F, 0.0F, 0.45F));
  // ||xi|| against xi_max, as text above the follower.
  const float shade = xi.norm() > design.xi_max ? 0.2F : 1.0F;  // red outside the bound
  visualization_msgs::Marker text = sphereMarker(
      frame, now, "bound", 0, Eigen::Vector3d(0.0, 0.0, 1.2), 0.35, 1.0F, shade, shade, 1.0F);
  text.type = visualization_msgs::Marker::TEXT_VIEW_FACING;
  std::ostringstream label;
  label << std::fixed << std::setprecision(2) << "|xi| " << xi.norm() << " / xi_max "
        << design.xi_max << " m";
  text.text = label.str();
  markers.markers.push_back(text);
  marker_publisher_.publish(markers);
}

void FollowerNode::diagnose(diagnostic_updater::DiagnosticStatusWrapper& status) {
  // Called from onControlTick with mutex_ held.
  const ControllerDesign& design = controller_.design();
  if (!have_measurement_) {
    status.summary(diagnostic_msgs::DiagnosticStatus::ERROR, "no relative measurement yet");
  } else if (last_xi_norm_ > design.xi_max) {
    status.summary(diagnostic_msgs::DiagnosticStatus::ERROR, "relative error outside xi_max");
  } else if (!last_tick_fresh_) {
    status.summary(diagnostic_msgs::DiagnosticStatus::WARN, "relative measurement stale");
  } else if (!last_rejection_.empty()) {
    status.summary(diagnostic_msgs::DiagnosticStatus::WARN,
                   "rejecting measurements: " + last_rejection_);
  } else {
    status.summary(diagnostic_msgs::DiagnosticStatus::OK, "tracking");
  }
  status.add("xi_norm (m)", last_xi_norm_);
  status.add("xi_max (m)", design.xi_max);
  status.add("margin (m)", design.xi_max - last_xi_norm_);
  status.add("estimate_norm (m)", controller_.status().estimate_norm);
  status.add("projection_active", controller_.status().projection_active);
  status.add("command_saturated", controller_.status().command_saturated);
  status.add("tracker_enabled", parameters_.tracker_enabled);
  status.add("rejected_measurements", rejected_measurements_);
  status.add("measurement_age (s)",
             have_measurement_ ? (ros::Time::now() - measurement_stamp_).toSec() : -1.0);
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
    if (config.tracker_natural_frequency > 0.0) {
      if (!candidate.model.C.isIdentity(0.0)) {
        throw ParameterError("tracker_natural_frequency", "needs C = identity");
      }
      candidate.tracker_gain = doubleIntegratorGain(
          Eigen::VectorXd::Constant(axes_, config.tracker_natural_frequency),
          Eigen::VectorXd::Constant(axes_, config.tracker_damping), "tracker_natural_frequency");
    }
    controller_.setDesign(ControllerDesign::create(candidate));
    parameters_ = candidate;
    ROS_INFO_STREAM(ros::this_node::getName()
                    << ": reconfigured: tracker " << (candidate.tracker_enabled ? "on" : "off")
                    << ", alpha " << candidate.alpha << ", epsilon " << candidate.epsilon
                    << ", xi_max " << controller_.design().xi_max << " m");
    applied_config_ = config;
  } catch (const ParameterError& error) {
    ROS_ERROR_STREAM(ros::this_node::getName()
                     << ": reconfiguration refused, previous values kept: " << error.what());
    config = applied_config_;
  }
}

}  // namespace projection_collision_avoidance
