#pragma once

/// @file
/// Conversions between the core's Eigen vectors and ROS messages, as free functions. Agents are
/// double integrators in k = 1..3 axes: state [p; v], positions along x, y, z in that order.

#include <cstddef>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>
#include <geometry_msgs/AccelStamped.h>
#include <geometry_msgs/TransformStamped.h>
#include <nav_msgs/Odometry.h>
#include <ros/time.h>
#include <visualization_msgs/Marker.h>

#include "projection_collision_avoidance/LeaderBroadcast.h"
#include "projection_collision_avoidance/NeighbourArray.h"
#include "projection_collision_avoidance/RelativeMeasurement.h"
#include "projection_collision_avoidance/cycle/LatchedInputs.hpp"
#include "projection_collision_avoidance/vehicle/RelativeStateFromOdometry.hpp"

namespace projection_collision_avoidance {

/// A float64[] field as an Eigen vector.
Eigen::VectorXd toEigen(const std::vector<double>& values);

/// An Eigen vector as a float64[] field.
std::vector<double> toStdVector(const Eigen::Ref<const Eigen::VectorXd>& values);

/// The first min(k, 3) entries of @p values on x, y, z; the rest zero.
Eigen::Vector3d toVector3(const Eigen::Ref<const Eigen::VectorXd>& values);

/// Relative state x_1 - x_2 = [position; velocity] of a measurement with @p axes entries each.
/// @return false, with the reason in @p why, for a wrong size or a non-finite entry
bool relativeStateFromMsg(const RelativeMeasurement& msg, int axes, Eigen::VectorXd* state,
                          std::string* why);

/// The leader's input u_1 (@p axes entries) and disturbance u_d (2 axes entries, or empty when
/// the leader does not know it) of a LeaderBroadcast, after checking the whole message: input
/// with @p axes entries; position and velocity both with @p axes entries or both empty (an agent
/// that does not know its own state, such as a follower in a chain); the disturbance empty or
/// with 2 axes entries; all finite.
/// @return false, with the reason in @p why, otherwise
bool leaderInputFromMsg(const LeaderBroadcast& msg, int axes, Eigen::VectorXd* input,
                        Eigen::VectorXd* disturbance, std::string* why);

/// Most entries a NeighbourArray may hold; a longer one is refused whole.
inline constexpr std::size_t kMaxNeighbourEntries = 1024;

/// The nearest NeighbourSample::kCapacity agents of a NeighbourArray into @p sample (agents,
/// count, sent; nearest first; the stamps are the caller's), after checking the whole message:
/// at most kMaxNeighbourEntries entries, each with @p axes entries of position and velocity, all
/// finite, none named @p self (the follower itself). The entry named @p target is marked as the
/// follower's target. @p order is scratch space (reserved once: no allocation after).
/// @return false, with the reason in @p why, otherwise (@p sample then unchanged)
bool neighbourSampleFromMsg(const NeighbourArray& msg, int axes, const std::string& self,
                            const std::string& target, NeighbourSample* sample,
                            std::vector<std::pair<double, std::size_t>>* order, std::string* why);

/// A RelativeMeasurement of the relative state [position; velocity] (2 axes entries).
RelativeMeasurement toRelativeMeasurementMsg(const Eigen::Ref<const Eigen::VectorXd>& state,
                                             const ros::Time& stamp, const std::string& frame);

/// The acceleration command (k entries) as AccelStamped (linear part; angular zero).
geometry_msgs::AccelStamped toAccelMsg(const Eigen::Ref<const Eigen::VectorXd>& command,
                                       const ros::Time& stamp, const std::string& frame);

/// The first @p axes linear entries of an AccelStamped.
/// @return false, with the reason in @p why, for a non-finite entry or a non-zero entry beyond
///         the model's axes
bool commandFromAccelMsg(const geometry_msgs::AccelStamped& msg, int axes, Eigen::VectorXd* command,
                         std::string* why);

/// Odometry of an agent's state [p; v] (2 axes entries): pose position and twist linear, identity
/// orientation, in @p frame with child @p child_frame.
nav_msgs::Odometry toOdometryMsg(const Eigen::Ref<const Eigen::VectorXd>& state,
                                 const ros::Time& stamp, const std::string& frame,
                                 const std::string& child_frame);

/// Odometry as a real base publishes it (REP 105): pose (@p position, m, and the yaw quaternion
/// of @p yaw, rad) in @p frame, twist (@p body_linear, m/s, @p body_angular, rad/s) in the body
/// frame @p child_frame; covariances 0.
nav_msgs::Odometry toBodyOdometryMsg(const Eigen::Vector3d& position, double yaw,
                                     const Eigen::Vector3d& body_linear,
                                     const Eigen::Vector3d& body_angular, const ros::Time& stamp,
                                     const std::string& frame, const std::string& child_frame);

/// The state [p; v] (2 axes entries) of an Odometry; false if non-finite.
bool stateFromOdometryMsg(const nav_msgs::Odometry& msg, int axes, Eigen::VectorXd* state);

/// An Odometry as the vehicle layer's OdometrySample (stamp, pose, twist as they are; the
/// checks of finiteness and unit quaternions are RelativeStateFromOdometry's).
OdometrySample toOdometrySample(const nav_msgs::Odometry& msg);

/// Colour of a marker: red, green, blue, alpha in [0, 1].
struct MarkerColor {
  float r = 1.0F;
  float g = 1.0F;
  float b = 1.0F;
  float a = 1.0F;
};

/// A marker of @p type (visualization_msgs::Marker::SPHERE, ...) at @p position in @p frame,
/// scaled @p size on every axis, frame-locked (it follows its tf frame between updates).
visualization_msgs::Marker toMarker(const std::string& frame, const ros::Time& stamp,
                                    const std::string& ns, int id, int type,
                                    const Eigen::Vector3d& position, double size,
                                    const MarkerColor& color);

/// The transform of a frame at @p position (1-3 entries) with identity rotation.
geometry_msgs::TransformStamped toTransformMsg(const Eigen::Ref<const Eigen::VectorXd>& position,
                                               const ros::Time& stamp, const std::string& parent,
                                               const std::string& child);

/// The transform of a frame at @p position (m) turned by @p yaw (rad) about z.
geometry_msgs::TransformStamped toTransformMsg(const Eigen::Vector3d& position, double yaw,
                                               const ros::Time& stamp, const std::string& parent,
                                               const std::string& child);

}  // namespace projection_collision_avoidance
