#include "projection_collision_avoidance/vehicle/Rotation.hpp"

#include <cmath>

namespace projection_collision_avoidance {

QuaternionStatus normaliseQuaternion(Eigen::Quaterniond& q, double tolerance) {
  if (!q.coeffs().allFinite()) {
    return QuaternionStatus::kNotFinite;
  }
  const double norm = q.coeffs().norm();
  // Written so that a NaN tolerance refuses.
  if (!(std::abs(norm - 1.0) <= tolerance) || !(norm > 0.0)) {
    return QuaternionStatus::kNotUnit;
  }
  q.coeffs() /= norm;
  return QuaternionStatus::kUnit;
}

const char* toString(QuaternionStatus status) {
  switch (status) {
    case QuaternionStatus::kUnit:
      return "unit";
    case QuaternionStatus::kNotFinite:
      return "not_finite";
    case QuaternionStatus::kNotUnit:
      return "not_unit";
  }
  return "unknown";
}

Eigen::Vector3d bodyToWorld(const Eigen::Quaterniond& q, const Eigen::Vector3d& v_body) {
  return q.toRotationMatrix() * v_body;
}

Eigen::Vector3d worldToBody(const Eigen::Quaterniond& q, const Eigen::Vector3d& v_world) {
  return q.toRotationMatrix().transpose() * v_world;
}

double yawOf(const Eigen::Quaterniond& q) {
  return std::atan2(2.0 * (q.w() * q.z() + q.x() * q.y()),
                    1.0 - 2.0 * (q.y() * q.y() + q.z() * q.z()));
}

}  // namespace projection_collision_avoidance
