#pragma once

/// @file
/// Differential-drive (unicycle) robots as double integrators: the controlled point is the
/// look-ahead point p_l = p + l [cos θ, sin θ] a distance l ahead of the axle's midpoint p, whose
/// velocity the robot can set freely through (v, ω) (doc/vehicles.md).

#include <limits>

#include <Eigen/Core>

namespace projection_collision_avoidance {

/// Pose of a unicycle in the world plane: the axle's midpoint (x, y) (m) and heading θ (rad).
struct UnicyclePose {
  double x = 0.0;
  double y = 0.0;
  double theta = 0.0;
};

/// Body velocities of a unicycle: forward speed v (m/s, negative backwards), yaw rate ω (rad/s).
struct UnicycleVelocity {
  double v = 0.0;
  double omega = 0.0;
};

/// Limits of a unicycle's commands: |v| ≤ max_speed (m/s), |ω| ≤ max_yaw_rate (rad/s); each
/// > 0, infinity for none.
struct UnicycleLimits {
  double max_speed = std::numeric_limits<double>::infinity();
  double max_yaw_rate = std::numeric_limits<double>::infinity();
};

/// A command for the robot (cmd_vel's linear.x and angular.z) and what the limits did to it.
struct UnicycleCommand {
  UnicycleVelocity velocity;      ///< to send: s · (v*, ω*) of the unlimited inverse
  double scale = 1.0;             ///< s ∈ [0, 1]; 1: not limited
  bool speed_limited = false;     ///< |v*| > max_speed
  bool yaw_rate_limited = false;  ///< |ω*| > max_yaw_rate
  bool refused = false;           ///< θ, ṗ_l or (v*, ω*) not finite: a zero command
};

/// The look-ahead map of a unicycle with look-ahead distance l and its inverse.
class UnicycleLookAhead {
 public:
  /// @param distance l (m), finite and > 0
  /// @param limits each finite and > 0, or infinity
  /// @throws ParameterError naming vehicle.unicycle.look_ahead_distance, .max_speed or
  ///         .max_yaw_rate
  explicit UnicycleLookAhead(double distance, const UnicycleLimits& limits = UnicycleLimits());

  /// The look-ahead point (m): p_l = p + l [cos θ, sin θ].
  Eigen::Vector2d point(const UnicyclePose& pose) const;

  /// Its velocity (m/s) for body velocities (v, ω):
  /// ṗ_l = [v cos θ − l ω sin θ, v sin θ + l ω cos θ].
  Eigen::Vector2d velocity(double theta, const UnicycleVelocity& body) const;

  /// Its velocity (m/s) from the axle's world velocity ṗ (m/s), which may slip sideways, and
  /// ω (rad/s): ṗ_l = ṗ + l ω [−sin θ, cos θ]. Equals velocity() when ṗ = v [cos θ, sin θ].
  Eigen::Vector2d velocityFromWorld(double theta, const Eigen::Vector2d& axle_velocity,
                                    double omega) const;

  /// The state [p_l; ṗ_l] (m, m/s) of the look-ahead point, a planar double integrator's state.
  Eigen::Vector4d state(const UnicyclePose& pose, const UnicycleVelocity& body) const;

  /// The inverse of velocity(), no limits (m/s, rad/s):
  /// [v, ω] = [[cos θ, sin θ], [−sin θ / l, cos θ / l]] ṗ_l.
  UnicycleVelocity inverse(double theta, const Eigen::Vector2d& look_ahead_velocity) const;

  /// The command for a wanted look-ahead velocity ṗ_l (m/s): inverse(), then v and ω scaled by
  /// the same s = min(1, max_speed / |v*|, max_yaw_rate / |ω*|), so that the look-ahead point
  /// still moves along ṗ_l, at s ‖ṗ_l‖ (the map is linear). Never throws; a θ or ṗ_l that is not
  /// finite, or (v*, ω*) that overflow, give a zero command, refused.
  UnicycleCommand command(double theta, const Eigen::Vector2d& look_ahead_velocity) const;

  double distance() const { return distance_; }
  const UnicycleLimits& limits() const { return limits_; }

 private:
  double distance_;
  UnicycleLimits limits_;
};

/// What a perimeter kept by two controlled points guarantees for their agents' reference points
/// (the axles' midpoints), each controlled point at a fixed distance l_i from its reference point:
/// ‖p_1 − p_2‖ ≥ ‖p_l1 − p_l2‖ − l_self − l_target (triangle inequality; equality when the
/// robots stand back to back on one line, each controlled point beyond its axle).
/// @return max(0, look_ahead_distance − l_self − l_target) (m), a lower bound on ‖p_1 − p_2‖
double referenceDistanceLowerBound(double look_ahead_distance, double l_self, double l_target);

/// The perimeter (m) the controlled points must keep so that the reference points keep
/// @p reference_perimeter (m): reference_perimeter + l_self + l_target. A holonomic target
/// controlled at its reference point has l_target = 0, and the perimeter grows by l_self.
double lookAheadPerimeter(double reference_perimeter, double l_self, double l_target);

}  // namespace projection_collision_avoidance
