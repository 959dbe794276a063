#pragma once

/// @file
/// The relative state x_target − x_self of two agents from their odometry (nav_msgs/Odometry
/// without ROS): positions in one world frame, velocities rotated from each body frame into it,
/// the two samples aligned to a common time. The input of the follower's `odometry` adapter
/// (doc/vehicles.md).

#include <cstdint>
#include <string>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "projection_collision_avoidance/core/TypeDefs.hpp"

namespace projection_collision_avoidance {

/// One odometry sample as REP 105 defines nav_msgs/Odometry: the pose in the world frame
/// (header.frame_id), the twist in the body frame (child_frame_id).
struct OdometrySample {
  double stamp = 0.0;                                  ///< header.stamp (s)
  Eigen::Vector3d position = Eigen::Vector3d::Zero();  ///< pose.position, world frame (m)
  /// pose.orientation: rotates body-frame vectors into the world frame
  Eigen::Quaterniond orientation = Eigen::Quaterniond::Identity();
  Eigen::Vector3d linear_velocity = Eigen::Vector3d::Zero();   ///< twist.linear (m/s)
  Eigen::Vector3d angular_velocity = Eigen::Vector3d::Zero();  ///< twist.angular (rad/s)
};

/// The frame the twist of an OdometrySample is expressed in.
enum class TwistFrame {
  kBody,   ///< child_frame_id, as REP 105 says (diff_drive_controller, MAVROS local_position/odom)
  kWorld,  ///< header.frame_id (some motion-capture relays); no rotation is applied
};

/// Where the pose of an odometry (and a twist in its header frame) is taken to be
/// (~odometry/pose_frame).
enum class PoseFrame : std::uint8_t {
  kHeader,  ///< "header": in header.frame_id, as REP 105 says
  kWorld,   ///< "world": in the node's world frame whatever header.frame_id says (a simulator's
            ///< ground truth labelled with the robot's own frame)
};

/// "header" or "world".
const char* toString(PoseFrame frame);

/// The PoseFrame named @p value ("header" or "world").
/// @throws ParameterError naming ~odometry/pose_frame for any other value
PoseFrame poseFrameOf(const std::string& value);

/// Options of RelativeStateFromOdometry.
struct OdometryAlignmentOptions {
  int axes = 2;                        ///< 1 (x: a line), 2 (x, y: ground robots) or 3 (x, y, z)
  double max_skew = 0.05;              ///< largest |t_target − t_self| aligned (s), ≥ 0
  double quaternion_tolerance = 1e-2;  ///< largest |‖q‖ − 1| normalised (dimensionless), ≥ 0
  TwistFrame twist_frame = TwistFrame::kBody;
  /// The controlled point of each agent, fixed in its body frame (m): zero for the odometry's
  /// origin, [l, 0, 0] for the look-ahead point of a unicycle (UnicycleLookAhead).
  Eigen::Vector3d self_point = Eigen::Vector3d::Zero();
  Eigen::Vector3d target_point = Eigen::Vector3d::Zero();
};

/// Why compute() accepted or refused a pair of samples.
enum class OdometryVerdict {
  kAccepted,
  kSelfNotFinite,  ///< a NaN or infinite stamp, position, orientation or velocity
  kTargetNotFinite,
  kSelfQuaternionNotUnit,  ///< |‖q‖ − 1| beyond quaternion_tolerance
  kTargetQuaternionNotUnit,
  kSkewTooLarge,  ///< |t_target − t_self| > max_skew
  kOverflow,      ///< finite samples whose aligned difference is not finite
};

/// A short reason: "accepted", "self_not_finite", ..., "skew_too_large", "overflow".
const char* toString(OdometryVerdict verdict);

/// x = [p; v] of the controlled points, 2 · axes entries (m, m/s), stored inline.
using PlanarOrSpatialState = BoundedMatrix<Eigen::Dynamic, 1, 6, 1>;

/// What compute() gives. Only verdict is meaningful unless accepted().
struct RelativeOdometryResult {
  OdometryVerdict verdict = OdometryVerdict::kAccepted;
  double stamp = 0.0;                ///< the common time, the newer of the two stamps (s)
  double skew = 0.0;                 ///< |t_target − t_self| (s); NaN if a stamp is not finite
  bool target_extrapolated = false;  ///< the target's sample was the older one
  bool self_extrapolated = false;    ///< the follower's own sample was the older one
  PlanarOrSpatialState state;        ///< x_target − x_self at stamp = [Δp; Δv] (m, m/s)

  bool accepted() const { return verdict == OdometryVerdict::kAccepted; }
};

/// World-frame position and velocity (m, m/s) of the point r fixed in the body of a sample with a
/// unit orientation q: p_r = p + R(q) r,  v_r = v_world + ω_world × R(q) r, where
/// v_world = R(q) v (or v for TwistFrame::kWorld) and likewise ω_world.
Eigen::Matrix<double, 6, 1> bodyPointState(const OdometrySample& sample, const Eigen::Vector3d& r,
                                           TwistFrame twist_frame);

/// The state x = [p; v] (2 · @p axes entries; m, m/s) of one odometry's origin, in the frame of
/// its pose: p as it is, v_world = R(q) v for TwistFrame::kBody (q checked against
/// @p quaternion_tolerance, then normalised) or v as it is for kWorld (q unused). The follower's
/// own state for the time headway. Never throws, allocates nothing.
/// @return kAccepted; kSelfNotFinite for a NaN or infinite position or velocity (or orientation,
///         for a body twist); kSelfQuaternionNotUnit; kOverflow for a finite velocity whose
///         rotation is not (components near the largest double)
OdometryVerdict originState(const OdometrySample& sample, TwistFrame twist_frame,
                            double quaternion_tolerance, int axes, PlanarOrSpatialState* state);

/// The relative state x_target − x_self from one odometry sample of each agent.
///
/// Model: each controlled point moves at constant velocity between the two stamps, so the older
/// sample is moved to the newer stamp, p ← p + v Δt, v unchanged (Δt = the skew). If the points
/// accelerate by at most a (m/s²) over the skew, the aligned state is off by at most ½ a Δt² in
/// position and a Δt in velocity; max_skew bounds that error. A skew exactly at max_skew is
/// aligned, beyond it refused. Samples are checked (finite, quaternions within the tolerance,
/// then normalised) and refused with a verdict; compute() never throws and allocates nothing.
/// Both poses must be in the same world frame (the ROS layer's tf2 lookup makes them so). In 2-D
/// the x, y components of the world-frame position and velocity are taken (z is dropped), in 1-D
/// x alone.
class RelativeStateFromOdometry {
 public:
  /// @throws ParameterError naming vehicle.odometry.axes (not 1, 2 or 3), .max_skew or
  ///         .quaternion_tolerance (negative or not finite), .self_point or .target_point
  ///         (not finite)
  explicit RelativeStateFromOdometry(const OdometryAlignmentOptions& options);

  /// x_target − x_self at the newer stamp, or a refusal.
  RelativeOdometryResult compute(const OdometrySample& self, const OdometrySample& target) const;

  const OdometryAlignmentOptions& options() const { return options_; }

 private:
  OdometryAlignmentOptions options_;
};

}  // namespace projection_collision_avoidance
