#include "projection_collision_avoidance/ros/LeaderNode.hpp"

#include <boost/make_shared.hpp>
#include <geometry_msgs/AccelStamped.h>

#include "projection_collision_avoidance/LeaderBroadcast.h"
#include "projection_collision_avoidance/core/ParameterError.hpp"
#include "projection_collision_avoidance/cycle/FrameNames.hpp"
#include "projection_collision_avoidance/ros/MessageConversions.hpp"
#include "projection_collision_avoidance/ros/RosParameters.hpp"
#include "projection_collision_avoidance/ros/ScenarioParameters.hpp"

namespace projection_collision_avoidance {
namespace {

LeaderNodeOptions readOptions(NodeOptionReader& reader, const Scenario& scenario) {
  LeaderNodeOptions o;
  o.rate = reader.number("rate", scenario.controller.control_rate, 1.0, 10000.0);
  o.leader_frame = reader.frame("leader_frame", o.leader_frame);
  if (o.leader_frame.empty()) {
    throw ParameterError("~leader_frame", "must not be empty");
  }
  o.share_disturbance = reader.boolean("share_disturbance", o.share_disturbance);
  o.max_future_stamp = reader.number("max_future_stamp", o.max_future_stamp, 0.0, 3600.0);
  return o;
}

}  // namespace

LeaderNode::LeaderNode(ros::NodeHandle nh, ros::NodeHandle private_nh)
    : nh_(nh),
      name_(ros::this_node::getName()),
      scenario_(loadDoubleIntegratorScenario(private_nh)),
      axes_(scenario_.controller.model.double_integrator_axes) {
  NodeOptionReader reader(private_nh);
  options_ = readOptions(reader, scenario_);
  odometry_timeline_ = InputTimeline(
      "leader/odom", InputTimelineOptions{{"", options_.max_future_stamp, 0.0, true}, {}, false});
  echoScenario(name_, private_nh);
  reader.echo(name_);

  command_publisher_.advertise<geometry_msgs::AccelStamped>(nh_, "leader/command", 10);
  broadcast_publisher_.advertise<LeaderBroadcast>(nh_, "leader/broadcast", 10);
  odometry_subscriber_ = nh_.subscribe("leader/odom", 10, &LeaderNode::onOdometry, this,
                                       ros::TransportHints().tcpNoDelay());
  timer_ = nh_.createTimer(ros::Duration(1.0 / options_.rate), &LeaderNode::onTick, this);
  ROS_INFO_STREAM(name_ << ": playing the leader's input at " << options_.rate << " Hz, " << axes_
                        << " axes, " << scenario_.leader_input.pulses.size() << " pulse(s) and "
                        << scenario_.leader_input.sinusoids.size() << " sinusoid(s); disturbance "
                        << (options_.share_disturbance ? "shared" : "not shared"));
}

void LeaderNode::onOdometry(const ros::MessageEvent<nav_msgs::Odometry const>& event) {
  const nav_msgs::Odometry::ConstPtr& msg = event.getConstMessage();
  const std::lock_guard<std::mutex> lock(mutex_);
  admitGuarded(odometry_timeline_, name_, [&] {
    const ros::Time now = ros::Time::now();
    if (!checkHeader(odometry_timeline_, msg->header, now, publisherOf(event))) {
      return;
    }
    if (!sameFrame(msg->child_frame_id, options_.leader_frame)) {
      odometry_timeline_.reject(Rejection::kContent,
                                "child_frame_id '" +
                                    boundedText(msg->child_frame_id, InputGuard::kMaxQuotedLength) +
                                    "', expected '" + options_.leader_frame + "'");
      return;
    }
    Eigen::VectorXd state;
    if (!stateFromOdometryMsg(*msg, axes_, &state)) {
      odometry_timeline_.reject(Rejection::kContent, "non-finite position or velocity");
      return;
    }
    odometry_ = *msg;
    state_ = state;
    have_odometry_ = true;
    odometry_fresh_ = true;
    odometry_timeline_.accept();
  });
}

void LeaderNode::onTick(const ros::TimerEvent& event) {
  const std::lock_guard<std::mutex> lock(mutex_);
  // The tick's time: the ROS time at which it runs. (current_expected can lag far behind after a
  // jump of ROS time, such as the first /clock; under sim time a timer also polls only every
  // wall millisecond, so it skips ticks when simulated time runs faster than 1 / rate per ms.)
  const ros::Time stamp = event.current_real;
  if (stamp.isZero() || (started_ && stamp == last_stamp_)) {
    return;
  }
  if (wentBack(tick_time_, stamp)) {
    // A restarted /clock, say: follow it, and forget the odometry of the old time line.
    ROS_WARN_STREAM(name_ << ": ROS time went back from " << last_stamp_.toSec() << " s to "
                          << stamp.toSec() << " s");
    have_odometry_ = false;
    odometry_timeline_.restart();
  }
  last_stamp_ = stamp;
  if (!started_) {
    started_ = true;
    origin_ = ros::Time::isSimTime() ? ros::Time(0) : stamp;
  }
  const double t = secondsBetween(stamp, origin_);
  const Eigen::VectorXd input = scenario_.leader_input.value(t, axes_);
  // Shared pointers: a subscriber in the same process gets the message itself (no copy).
  command_publisher_.publish(boost::make_shared<geometry_msgs::AccelStamped>(
      toAccelMsg(input, stamp, options_.leader_frame)));
  if (!have_odometry_ || !odometry_fresh_) {
    return;  // one broadcast per odometry: its stamp is the odometry's, and a repeat is refused
  }
  odometry_fresh_ = false;
  if (!broadcast_publisher_.subscribed()) {
    return;
  }
  auto broadcast = boost::make_shared<LeaderBroadcast>();
  broadcast->header = odometry_.header;
  broadcast->position = toStdVector(state_.head(axes_));
  broadcast->velocity = toStdVector(state_.tail(axes_));
  broadcast->input = toStdVector(input);
  if (options_.share_disturbance) {
    broadcast->disturbance = toStdVector(scenario_.disturbance.value(t, 2 * axes_));
  }
  broadcast_publisher_.publish(broadcast);
}

}  // namespace projection_collision_avoidance
