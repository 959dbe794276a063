#include "plant/PlantVehicles.hpp"

#include <cmath>
#include <utility>

#include <nav_msgs/Odometry.h>
#include <tf2_eigen/tf2_eigen.h>

#include "projection_collision_avoidance/ros/InputAdmission.hpp"
#include "projection_collision_avoidance/ros/MessageConversions.hpp"

namespace projection_collision_avoidance {
namespace {

/// A velocity across the unicycle's heading smaller than this (m/s) is not worth a warning.
constexpr double kDroppedVelocityTolerance = 1e-9;

bool allFinite(const geometry_msgs::Twist& twist) {
  return std::isfinite(twist.linear.x) && std::isfinite(twist.linear.y) &&
         std::isfinite(twist.linear.z) && std::isfinite(twist.angular.x) &&
         std::isfinite(twist.angular.y) && std::isfinite(twist.angular.z);
}

/// R_z(ψ) v.
Eigen::Vector3d turned(double psi, const Eigen::Vector3d& v) {
  const double c = std::cos(psi);
  const double s = std::sin(psi);
  return {c * v.x() - s * v.y(), s * v.x() + c * v.y(), v.z()};
}

}  // namespace

PlantVehicle::PlantVehicle(const VehicleOptions& options, Setup setup,
                           const Eigen::VectorXd& initial_state)
    : kind_(options.kind),
      twist_in_body_(options.twist_in_body),
      setup_(std::move(setup)),
      odom_frame_(options.odom_frame),
      // Jumps back of the plant's time come from its clock (restartTimeline()).
      twist_timeline_(setup_.agent_name + "/cmd_vel",
                      {InputGuardLimits{}, {}, false, setup_.command_timeout}),
      stamped_timeline_(
          setup_.agent_name + "/cmd_vel_stamped",
          {{"", setup_.command_timeout, setup_.command_timeout}, setup_.clock_skew, false}) {
  const int k = setup_.axes;
  const Eigen::Vector3d p0 = toVector3(initial_state.head(k));
  const Eigen::Vector3d v0 = toVector3(initial_state.tail(k));
  odom_origin_ = p0;
  odom_yaw_ = options.heading;
  if (kind_ == VehicleKind::kVelocity) {
    velocity_.emplace(
        k, p0, v0, VelocityLagParameters{options.velocity_lag, options.max_speed, options.heading},
        options.key);
    return;
  }
  UnicycleState start;
  start.x = p0.x();
  start.y = p0.y();
  start.theta = options.heading;
  start.v = v0.x() * std::cos(options.heading) + v0.y() * std::sin(options.heading);
  z_ = p0.z();
  unicycle_.emplace(
      start, UnicycleParameters{options.velocity_lag, options.max_speed, options.max_yaw_rate},
      options.key);
  const double across = -v0.x() * std::sin(options.heading) + v0.y() * std::cos(options.heading);
  if (std::abs(across) > kDroppedVelocityTolerance ||
      std::abs(v0.z()) > kDroppedVelocityTolerance) {
    ROS_WARN_STREAM(setup_.node_name << ": " << setup_.agent_name
                                     << " is a unicycle: of its initial velocity only the part "
                                        "along its heading is kept, "
                                     << start.v << " m/s");
  }
}

void PlantVehicle::connect(ros::NodeHandle& nh, std::mutex* mutex, std::function<ros::Time()> now) {
  mutex_ = mutex;
  now_ = std::move(now);
  const std::string& agent = setup_.agent_name;
  odom_publisher_ = nh.advertise<nav_msgs::Odometry>(agent + "/odom", 10);
  applied_publisher_ = nh.advertise<geometry_msgs::TwistStamped>(agent + "/applied_command", 10);
  twist_subscriber_ = subscribeEvents<geometry_msgs::Twist>(
      nh, agent + "/cmd_vel", 10,
      [this](const ros::MessageEvent<geometry_msgs::Twist const>& event) {
        onTwist(*event.getConstMessage(), publisherOf(event));
      });
  stamped_subscriber_ = subscribeEvents<geometry_msgs::TwistStamped>(
      nh, agent + "/cmd_vel_stamped", 10,
      [this](const ros::MessageEvent<geometry_msgs::TwistStamped const>& event) {
        onTwistStamped(*event.getConstMessage(), publisherOf(event));
      });
}

bool PlantVehicle::commandOf(const geometry_msgs::Twist& twist, Eigen::Vector3d* command,
                             std::string* why) const {
  if (!allFinite(twist)) {
    *why = "non-finite field";
    return false;
  }
  if (kind_ == VehicleKind::kUnicycle) {
    *command = Eigen::Vector3d(twist.linear.x, twist.angular.z, 0.0);
    return true;
  }
  const Eigen::Vector3d linear(twist.linear.x, twist.linear.y, twist.linear.z);
  *command = twist_in_body_ ? turned(velocity_->heading(), linear) : linear;
  return true;
}

void PlantVehicle::onTwist(const geometry_msgs::Twist& twist, std::string_view publisher) {
  const std::lock_guard<std::mutex> lock(*mutex_);
  admitGuarded(twist_timeline_, setup_.node_name, [&] {
    const ros::Time now = now_();
    if (twist_timeline_.checkReceipt(nanosecondsOf(now), publisher)) {
      hold(&twist_timeline_, twist, now);
    }
  });
}

void PlantVehicle::onTwistStamped(const geometry_msgs::TwistStamped& message,
                                  std::string_view publisher) {
  const std::lock_guard<std::mutex> lock(*mutex_);
  admitGuarded(stamped_timeline_, setup_.node_name, [&] {
    const ros::Time now = now_();
    if (checkHeader(stamped_timeline_, message.header, now, publisher)) {
      hold(&stamped_timeline_, message.twist, now);
    }
  });
}

void PlantVehicle::hold(InputTimeline* timeline, const geometry_msgs::Twist& twist,
                        const ros::Time& now) {
  std::string why;
  Eigen::Vector3d command;
  if (!commandOf(twist, &command, &why)) {
    timeline->reject(Rejection::kContent, why);
    return;
  }
  if (!twist_timeline_.guard().everAccepted() && !stamped_timeline_.guard().everAccepted()) {
    ROS_INFO_STREAM(setup_.node_name << ": first " << setup_.agent_name << " velocity command");
  }
  command_ = command;
  have_command_ = true;
  received_ = now;
  timeline->accept();
}

Eigen::VectorXd PlantVehicle::state() const {
  const int k = setup_.axes;
  Eigen::VectorXd state(2 * k);
  if (velocity_) {
    state << velocity_->position().head(k), velocity_->velocity().head(k);
    return state;
  }
  const UnicycleState& s = unicycle_->state();
  const Eigen::Vector2d v = unicycle_->worldVelocity();
  state << Eigen::Vector3d(s.x, s.y, z_).head(k), Eigen::Vector3d(v.x(), v.y(), 0.0).head(k);
  return state;
}

double PlantVehicle::yaw() const {
  return velocity_ ? velocity_->heading() : unicycle_->state().theta;
}

void PlantVehicle::publishSample(const ros::Time& stamp,
                                 std::vector<geometry_msgs::TransformStamped>* transforms) const {
  Eigen::Vector3d position;
  Eigen::Vector3d linear;
  Eigen::Vector3d angular = Eigen::Vector3d::Zero();
  if (velocity_) {
    position = velocity_->position();
    linear = velocity_->bodyVelocity();
  } else {
    const UnicycleState& s = unicycle_->state();
    position = Eigen::Vector3d(s.x, s.y, z_);
    linear = Eigen::Vector3d(s.v, 0.0, 0.0);
    angular.z() = s.omega;
  }
  std::string frame = setup_.world_frame;
  double heading = yaw();
  if (!odom_frame_.empty()) {  // as a real base counts it: from where and how it started
    frame = odom_frame_;
    position = turned(-odom_yaw_, position - odom_origin_);
    heading -= odom_yaw_;
  }
  odom_publisher_.publish(
      toBodyOdometryMsg(position, heading, linear, angular, stamp, frame, setup_.frame));
  transforms->push_back(toTransformMsg(position, heading, stamp, frame, setup_.frame));
}

bool PlantVehicle::odomFrameTransform(const ros::Time& stamp,
                                      geometry_msgs::TransformStamped* transform) const {
  if (odom_frame_.empty()) {
    return false;
  }
  *transform = toTransformMsg(odom_origin_, odom_yaw_, stamp, setup_.world_frame, odom_frame_);
  return true;
}

void PlantVehicle::advance(double h, const ros::Time& stamp) {
  const bool fresh =
      have_command_ && std::abs(secondsBetween(stamp, received_)) <= setup_.command_timeout;
  if (fresh && timed_out_) {
    ROS_INFO_STREAM(setup_.node_name << ": " << setup_.agent_name
                                     << " velocity command fresh again");
    timed_out_ = false;
  } else if (!fresh && have_command_ && !timed_out_) {
    ROS_WARN_STREAM(setup_.node_name << ": " << setup_.agent_name << " velocity command is "
                                     << secondsBetween(stamp, received_)
                                     << " s old, more than ~command_timeout ("
                                     << setup_.command_timeout << " s): stopping");
    timed_out_ = true;
  }
  const Eigen::Vector3d command = fresh ? command_ : Eigen::Vector3d::Zero();
  geometry_msgs::TwistStamped applied;
  applied.header.stamp = stamp;
  if (velocity_) {
    velocity_->setCommand(command);
    velocity_->advance(h);
    applied.header.frame_id = setup_.world_frame;
    tf2::toMsg(velocity_->command(), applied.twist.linear);
  } else {
    unicycle_->setCommand(command.x(), command.y());
    unicycle_->advance(h);
    applied.header.frame_id = setup_.frame;
    applied.twist.linear.x = unicycle_->commandSpeed();
    applied.twist.angular.z = unicycle_->commandYawRate();
  }
  applied_publisher_.publish(applied);
}

void PlantVehicle::restartTimeline() {
  have_command_ = false;
  timed_out_ = false;
  twist_timeline_.restart();
  stamped_timeline_.restart();
}

}  // namespace projection_collision_avoidance
