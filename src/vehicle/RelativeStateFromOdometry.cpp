#include "projection_collision_avoidance/vehicle/RelativeStateFromOdometry.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "projection_collision_avoidance/core/ParameterError.hpp"
#include "projection_collision_avoidance/vehicle/Rotation.hpp"

namespace projection_collision_avoidance {
namespace {

/// Whether every number compute() uses of @p sample is finite; the angular velocity is used only
/// for a controlled point away from the body's origin.
bool sampleFinite(const OdometrySample& sample, const Eigen::Vector3d& point) {
  return std::isfinite(sample.stamp) && sample.position.allFinite() &&
         sample.orientation.coeffs().allFinite() && sample.linear_velocity.allFinite() &&
         (point.isZero(0.0) || sample.angular_velocity.allFinite());
}

void requireNonNegative(double value, const std::string& key, const char* unit) {
  if (!(value >= 0.0) || !std::isfinite(value)) {
    throw ParameterError(
        key, std::string("must be finite and >= 0 ") + unit + ", got " + std::to_string(value));
  }
}

}  // namespace

const char* toString(OdometryVerdict verdict) {
  switch (verdict) {
    case OdometryVerdict::kAccepted:
      return "accepted";
    case OdometryVerdict::kSelfNotFinite:
      return "self_not_finite";
    case OdometryVerdict::kTargetNotFinite:
      return "target_not_finite";
    case OdometryVerdict::kSelfQuaternionNotUnit:
      return "self_quaternion_not_unit";
    case OdometryVerdict::kTargetQuaternionNotUnit:
      return "target_quaternion_not_unit";
    case OdometryVerdict::kSkewTooLarge:
      return "skew_too_large";
    case OdometryVerdict::kOverflow:
      return "overflow";
  }
  return "unknown";
}

const char* toString(PoseFrame frame) { return frame == PoseFrame::kWorld ? "world" : "header"; }

PoseFrame poseFrameOf(const std::string& value) {
  if (value == "header") {
    return PoseFrame::kHeader;
  }
  if (value == "world") {
    return PoseFrame::kWorld;
  }
  throw ParameterError("~odometry/pose_frame",
                       "must be \"header\" (the pose in header.frame_id, REP 105) or \"world\" "
                       "(the pose in the node's world frame whatever header.frame_id says), "
                       "got \"" +
                           value + "\"");
}

Eigen::Matrix<double, 6, 1> bodyPointState(const OdometrySample& sample, const Eigen::Vector3d& r,
                                           TwistFrame twist_frame) {
  const Eigen::Matrix3d rotation = sample.orientation.toRotationMatrix();
  const bool body = twist_frame == TwistFrame::kBody;
  const Eigen::Vector3d velocity =
      body ? Eigen::Vector3d(rotation * sample.linear_velocity) : sample.linear_velocity;
  Eigen::Matrix<double, 6, 1> state;
  state.head<3>() = sample.position;
  state.tail<3>() = velocity;
  if (!r.isZero(0.0)) {
    const Eigen::Vector3d offset = rotation * r;
    const Eigen::Vector3d omega =
        body ? Eigen::Vector3d(rotation * sample.angular_velocity) : sample.angular_velocity;
    state.head<3>() += offset;
    state.tail<3>() += omega.cross(offset);
  }
  return state;
}

OdometryVerdict originState(const OdometrySample& sample, TwistFrame twist_frame,
                            double quaternion_tolerance, int axes, PlanarOrSpatialState* state) {
  const bool body = twist_frame == TwistFrame::kBody;
  if (!sample.position.allFinite() || !sample.linear_velocity.allFinite() ||
      (body && !sample.orientation.coeffs().allFinite())) {
    return OdometryVerdict::kSelfNotFinite;
  }
  Eigen::Vector3d velocity = sample.linear_velocity;
  if (body) {
    Eigen::Quaterniond q = sample.orientation;
    if (normaliseQuaternion(q, quaternion_tolerance) != QuaternionStatus::kUnit) {
      return OdometryVerdict::kSelfQuaternionNotUnit;
    }
    velocity = q.toRotationMatrix() * velocity;
    if (!velocity.allFinite()) {
      return OdometryVerdict::kOverflow;
    }
  }
  *state = PlanarOrSpatialState::Zero(2 * axes);
  state->head(axes) = sample.position.head(axes);
  state->tail(axes) = velocity.head(axes);
  return OdometryVerdict::kAccepted;
}

RelativeStateFromOdometry::RelativeStateFromOdometry(const OdometryAlignmentOptions& options)
    : options_(options) {
  if (options.axes < 1 || options.axes > 3) {
    throw ParameterError("vehicle.odometry.axes",
                         "must be 1, 2 or 3, got " + std::to_string(options.axes));
  }
  requireNonNegative(options.max_skew, "vehicle.odometry.max_skew", "s");
  requireNonNegative(options.quaternion_tolerance, "vehicle.odometry.quaternion_tolerance", "");
  if (!options.self_point.allFinite()) {
    throw ParameterError("vehicle.odometry.self_point", "must be finite");
  }
  if (!options.target_point.allFinite()) {
    throw ParameterError("vehicle.odometry.target_point", "must be finite");
  }
}

RelativeOdometryResult RelativeStateFromOdometry::compute(const OdometrySample& self,
                                                          const OdometrySample& target) const {
  RelativeOdometryResult result;
  const int k = options_.axes;
  result.state = PlanarOrSpatialState::Zero(2 * k);
  result.skew = std::numeric_limits<double>::quiet_NaN();
  if (!sampleFinite(self, options_.self_point)) {
    result.verdict = OdometryVerdict::kSelfNotFinite;
    return result;
  }
  if (!sampleFinite(target, options_.target_point)) {
    result.verdict = OdometryVerdict::kTargetNotFinite;
    return result;
  }
  OdometrySample own = self;
  OdometrySample other = target;
  if (normaliseQuaternion(own.orientation, options_.quaternion_tolerance) !=
      QuaternionStatus::kUnit) {
    result.verdict = OdometryVerdict::kSelfQuaternionNotUnit;
    return result;
  }
  if (normaliseQuaternion(other.orientation, options_.quaternion_tolerance) !=
      QuaternionStatus::kUnit) {
    result.verdict = OdometryVerdict::kTargetQuaternionNotUnit;
    return result;
  }
  // Finite stamps can still differ by more than DBL_MAX: then the skew is infinite and refused.
  const double newer = std::max(own.stamp, other.stamp);
  const double older = std::min(own.stamp, other.stamp);
  result.skew = newer - older;
  result.stamp = newer;
  if (!(result.skew <= options_.max_skew)) {
    result.verdict = OdometryVerdict::kSkewTooLarge;
    return result;
  }
  Eigen::Matrix<double, 6, 1> x_self =
      bodyPointState(own, options_.self_point, options_.twist_frame);
  Eigen::Matrix<double, 6, 1> x_target =
      bodyPointState(other, options_.target_point, options_.twist_frame);
  // Constant velocity over the skew: the older sample's point moves to the newer stamp.
  if (own.stamp < other.stamp) {
    x_self.head<3>() += x_self.tail<3>() * (other.stamp - own.stamp);
    result.self_extrapolated = true;
  } else if (other.stamp < own.stamp) {
    x_target.head<3>() += x_target.tail<3>() * (own.stamp - other.stamp);
    result.target_extrapolated = true;
  }
  const Eigen::Matrix<double, 6, 1> difference = x_target - x_self;
  if (!difference.allFinite()) {  // finite inputs whose difference overflows
    result.verdict = OdometryVerdict::kOverflow;
    return result;
  }
  result.state.head(k) = difference.head(k);
  result.state.tail(k) = difference.segment(3, k);
  result.verdict = OdometryVerdict::kAccepted;
  return result;
}

}  // namespace projection_collision_avoidance
