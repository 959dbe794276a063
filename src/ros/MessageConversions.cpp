#include "projection_collision_avoidance/ros/MessageConversions.hpp"

#include <algorithm>
#include <cmath>

#include <Eigen/Geometry>
#include <tf2_eigen/tf2_eigen.h>

namespace projection_collision_avoidance {

Eigen::VectorXd toEigen(const std::vector<double>& values) {
  return Eigen::Map<const Eigen::VectorXd>(values.data(), static_cast<Eigen::Index>(values.size()));
}

std::vector<double> toStdVector(const Eigen::Ref<const Eigen::VectorXd>& values) {
  return std::vector<double>(values.data(), values.data() + values.size());
}

Eigen::Vector3d toVector3(const Eigen::Ref<const Eigen::VectorXd>& values) {
  Eigen::Vector3d result = Eigen::Vector3d::Zero();
  const Eigen::Index count = std::min<Eigen::Index>(3, values.size());
  result.head(count) = values.head(count);
  return result;
}

bool relativeStateFromMsg(const RelativeMeasurement& msg, int axes, Eigen::VectorXd* state,
                          std::string* why) {
  if (static_cast<int>(msg.position.size()) != axes ||
      static_cast<int>(msg.velocity.size()) != axes) {
    *why = "position and velocity must have " + std::to_string(axes) + " entries, got " +
           std::to_string(msg.position.size()) + " and " + std::to_string(msg.velocity.size());
    return false;
  }
  Eigen::VectorXd result(2 * axes);
  result << toEigen(msg.position), toEigen(msg.velocity);
  if (!result.allFinite()) {
    *why = "non-finite entry";
    return false;
  }
  *state = result;
  return true;
}

bool leaderInputFromMsg(const LeaderBroadcast& msg, int axes, Eigen::VectorXd* input,
                        Eigen::VectorXd* disturbance, std::string* why) {
  const auto size = [](const std::vector<double>& field) { return std::to_string(field.size()); };
  const auto axes_entries = static_cast<std::size_t>(axes);
  const bool state_known =
      msg.position.size() == axes_entries && msg.velocity.size() == axes_entries;
  const bool state_unknown = msg.position.empty() && msg.velocity.empty();
  if (!(state_known || state_unknown) || msg.input.size() != axes_entries ||
      (!msg.disturbance.empty() && msg.disturbance.size() != 2 * axes_entries)) {
    *why = "input must have " + std::to_string(axes) + " entries, position and velocity " +
           std::to_string(axes) + " each or none, and disturbance 0 or " +
           std::to_string(2 * axes) + ", got " + size(msg.position) + ", " + size(msg.velocity) +
           ", " + size(msg.input) + " and " + size(msg.disturbance);
    return false;
  }
  for (const std::vector<double>* field :
       {&msg.position, &msg.velocity, &msg.input, &msg.disturbance}) {
    if (!toEigen(*field).allFinite()) {
      *why = "non-finite entry";
      return false;
    }
  }
  *input = toEigen(msg.input);
  *disturbance = toEigen(msg.disturbance);
  return true;
}

bool neighbourSampleFromMsg(const NeighbourArray& msg, int axes, const std::string& self,
                            const std::string& target, NeighbourSample* sample,
                            std::vector<std::pair<double, std::size_t>>* order, std::string* why) {
  const std::size_t entries = msg.neighbours.size();
  if (entries > kMaxNeighbourEntries) {
    *why =
        std::to_string(entries) + " neighbours, more than " + std::to_string(kMaxNeighbourEntries);
    return false;
  }
  const auto axes_entries = static_cast<std::size_t>(axes);
  order->clear();
  for (std::size_t e = 0; e < entries; ++e) {
    const Neighbour& entry = msg.neighbours[e];
    if (entry.position.size() != axes_entries || entry.velocity.size() != axes_entries) {
      *why = "neighbour " + std::to_string(e) + ": position and velocity must have " +
             std::to_string(axes) + " entries, got " + std::to_string(entry.position.size()) +
             " and " + std::to_string(entry.velocity.size());
      return false;
    }
    double squared = 0.0;
    bool finite = true;
    for (std::size_t a = 0; a < axes_entries; ++a) {
      squared += entry.position[a] * entry.position[a];
      finite = finite && std::isfinite(entry.position[a]) && std::isfinite(entry.velocity[a]);
    }
    if (!finite || !std::isfinite(squared)) {
      *why = "neighbour " + std::to_string(e) + ": non-finite entry";
      return false;
    }
    if (entry.id == self) {
      *why = "neighbour " + std::to_string(e) + " is the follower itself (id " + self + ")";
      return false;
    }
    order->emplace_back(squared, e);
  }
  // The nearest first; ties by their place in the message.
  const std::size_t kept = std::min<std::size_t>(entries, NeighbourSample::kCapacity);
  std::partial_sort(order->begin(), order->begin() + static_cast<std::ptrdiff_t>(kept),
                    order->end());
  for (std::size_t j = 0; j < kept; ++j) {
    const Neighbour& entry = msg.neighbours[(*order)[j].second];
    SensedAgent& agent = sample->agents[j];
    agent.position.setZero();
    agent.velocity.setZero();
    for (std::size_t a = 0; a < axes_entries; ++a) {
      agent.position(static_cast<Eigen::Index>(a)) = entry.position[a];
      agent.velocity(static_cast<Eigen::Index>(a)) = entry.velocity[a];
    }
    agent.target = entry.id == target;
    const std::size_t length = std::min(entry.id.size(), SensedAgent::kIdLength - 1);
    std::copy_n(entry.id.data(), length, agent.id.data());
    agent.id[length] = '\0';
  }
  sample->count = static_cast<int>(kept);
  sample->sent = static_cast<int>(entries);
  return true;
}

RelativeMeasurement toRelativeMeasurementMsg(const Eigen::Ref<const Eigen::VectorXd>& state,
                                             const ros::Time& stamp, const std::string& frame) {
  const Eigen::Index axes = state.size() / 2;
  RelativeMeasurement msg;
  msg.header.stamp = stamp;
  msg.header.frame_id = frame;
  msg.position = toStdVector(state.head(axes));
  msg.velocity = toStdVector(state.tail(axes));
  return msg;
}

geometry_msgs::AccelStamped toAccelMsg(const Eigen::Ref<const Eigen::VectorXd>& command,
                                       const ros::Time& stamp, const std::string& frame) {
  geometry_msgs::AccelStamped msg;
  msg.header.stamp = stamp;
  msg.header.frame_id = frame;
  tf2::toMsg(toVector3(command), msg.accel.linear);
  return msg;
}

bool commandFromAccelMsg(const geometry_msgs::AccelStamped& msg, int axes, Eigen::VectorXd* command,
                         std::string* why) {
  Eigen::Vector3d linear;
  tf2::fromMsg(msg.accel.linear, linear);
  if (!linear.allFinite()) {
    *why = "non-finite acceleration";
    return false;
  }
  if (!linear.tail(3 - axes).isZero()) {
    *why = "acceleration on an axis the model does not have (" + std::to_string(axes) + " axes)";
    return false;
  }
  *command = linear.head(axes);
  return true;
}

nav_msgs::Odometry toOdometryMsg(const Eigen::Ref<const Eigen::VectorXd>& state,
                                 const ros::Time& stamp, const std::string& frame,
                                 const std::string& child_frame) {
  const Eigen::Index axes = state.size() / 2;
  nav_msgs::Odometry msg;
  msg.header.stamp = stamp;
  msg.header.frame_id = frame;
  msg.child_frame_id = child_frame;
  msg.pose.pose.position = tf2::toMsg(toVector3(state.head(axes)));
  msg.pose.pose.orientation.w = 1.0;
  tf2::toMsg(toVector3(state.tail(axes)), msg.twist.twist.linear);
  return msg;
}

nav_msgs::Odometry toBodyOdometryMsg(const Eigen::Vector3d& position, double yaw,
                                     const Eigen::Vector3d& body_linear,
                                     const Eigen::Vector3d& body_angular, const ros::Time& stamp,
                                     const std::string& frame, const std::string& child_frame) {
  nav_msgs::Odometry msg;
  msg.header.stamp = stamp;
  msg.header.frame_id = frame;
  msg.child_frame_id = child_frame;
  msg.pose.pose.position = tf2::toMsg(position);
  msg.pose.pose.orientation =
      tf2::toMsg(Eigen::Quaterniond(Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ())));
  tf2::toMsg(body_linear, msg.twist.twist.linear);
  tf2::toMsg(body_angular, msg.twist.twist.angular);
  return msg;
}

bool stateFromOdometryMsg(const nav_msgs::Odometry& msg, int axes, Eigen::VectorXd* state) {
  Eigen::Vector3d position;
  Eigen::Vector3d velocity;
  tf2::fromMsg(msg.pose.pose.position, position);
  tf2::fromMsg(msg.twist.twist.linear, velocity);
  if (!position.allFinite() || !velocity.allFinite()) {
    return false;
  }
  state->resize(2 * axes);
  *state << position.head(axes), velocity.head(axes);
  return true;
}

OdometrySample toOdometrySample(const nav_msgs::Odometry& msg) {
  OdometrySample sample;
  sample.stamp = msg.header.stamp.toSec();
  tf2::fromMsg(msg.pose.pose.position, sample.position);
  const geometry_msgs::Quaternion& q = msg.pose.pose.orientation;
  sample.orientation = Eigen::Quaterniond(q.w, q.x, q.y, q.z);
  tf2::fromMsg(msg.twist.twist.linear, sample.linear_velocity);
  tf2::fromMsg(msg.twist.twist.angular, sample.angular_velocity);
  return sample;
}

geometry_msgs::TransformStamped toTransformMsg(const Eigen::Ref<const Eigen::VectorXd>& position,
                                               const ros::Time& stamp, const std::string& parent,
                                               const std::string& child) {
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.translation() = toVector3(position);
  geometry_msgs::TransformStamped msg = tf2::eigenToTransform(pose);
  msg.header.stamp = stamp;
  msg.header.frame_id = parent;
  msg.child_frame_id = child;
  return msg;
}

geometry_msgs::TransformStamped toTransformMsg(const Eigen::Vector3d& position, double yaw,
                                               const ros::Time& stamp, const std::string& parent,
                                               const std::string& child) {
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.translation() = position;
  pose.linear() = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  geometry_msgs::TransformStamped msg = tf2::eigenToTransform(pose);
  msg.header.stamp = stamp;
  msg.header.frame_id = parent;
  msg.child_frame_id = child;
  return msg;
}

visualization_msgs::Marker toMarker(const std::string& frame, const ros::Time& stamp,
                                    const std::string& ns, int id, int type,
                                    const Eigen::Vector3d& position, double size,
                                    const MarkerColor& color) {
  visualization_msgs::Marker marker;
  marker.header.frame_id = frame;
  marker.header.stamp = stamp;
  marker.ns = ns;
  marker.id = id;
  marker.type = type;
  marker.action = visualization_msgs::Marker::ADD;
  marker.pose.position.x = position.x();
  marker.pose.position.y = position.y();
  marker.pose.position.z = position.z();
  marker.pose.orientation.w = 1.0;
  marker.frame_locked = true;
  marker.scale.x = marker.scale.y = marker.scale.z = size;
  marker.color.r = color.r;
  marker.color.g = color.g;
  marker.color.b = color.b;
  marker.color.a = color.a;
  return marker;
}

}  // namespace projection_collision_avoidance
