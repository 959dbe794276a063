#pragma once

/// @file
/// Orientations of odometry poses (REP 103, REP 105): the unit quaternion q of a pose rotates
/// vectors of the body frame (the message's child_frame_id) into the world frame (its
/// header.frame_id), v_world = R(q) v_body.

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace projection_collision_avoidance {

/// What normaliseQuaternion() found.
enum class QuaternionStatus {
  kUnit,       ///< usable: |‖q‖ − 1| ≤ tolerance; q now divided by ‖q‖
  kNotFinite,  ///< a coefficient is NaN or infinite: refused, q unchanged
  kNotUnit,    ///< |‖q‖ − 1| > tolerance (the all-zero quaternion among them): refused
};

/// Makes @p q of unit length, q ← q / ‖q‖, when |‖q‖ − 1| ≤ @p tolerance (dimensionless, ≥ 0);
/// refuses it otherwise and leaves it unchanged. Never throws.
QuaternionStatus normaliseQuaternion(Eigen::Quaterniond& q, double tolerance);

/// "not_finite", "not_unit" or "unit".
const char* toString(QuaternionStatus status);

/// v_world = R(q) v_body for a unit quaternion q (body → world); any unit (m/s, rad/s).
Eigen::Vector3d bodyToWorld(const Eigen::Quaterniond& q, const Eigen::Vector3d& v_body);

/// v_body = R(q)ᵀ v_world for a unit quaternion q (body → world); any unit (m/s, rad/s).
Eigen::Vector3d worldToBody(const Eigen::Quaterniond& q, const Eigen::Vector3d& v_world);

/// Yaw ψ (rad, in [−π, π]) of a unit q: the heading in the world x-y plane of the body x axis,
/// ψ = atan2(2 (w z + x y), 1 − 2 (y² + z²)).
double yawOf(const Eigen::Quaterniond& q);

}  // namespace projection_collision_avoidance
