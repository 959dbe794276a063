#pragma once

/// @file
/// Convoys on the target's path (doc/math.md, "Convoys on the target's path"): with
/// formation.slots: path a follower keeps to the path its target drove (TargetPath, (C1)), an arc
/// gap behind the target, at a goal point never closer to the target than (1 + margin_ratio)
/// ||d_i|| (C2).
/// It tracks a reference point r, its own state, that follows the goal with a bounded
/// acceleration (C3); its slot is D = x_target − [r; r'] and its known input u_r = r'' (C4), so
/// that xi = [r − p_i; r' − v_i] obeys the paper's relative dynamics with no unknown input.

#include <string>

#include <Eigen/Core>

#include "projection_collision_avoidance/core/TargetPath.hpp"

namespace projection_collision_avoidance {

/// The convoy's parameters (formation.path).
struct ConvoyParameters {
  /// The arc gap g_i = gap_ratio ||d_i|| (m) behind the target along its path; at least
  /// 1 + margin_ratio.
  double gap_ratio = 1.5;
  /// The goal keeps a chord (1 + margin_ratio) ||d_i|| from the target, and the reference's
  /// braking barrier (C5) a chord c_min = (1 + margin_ratio / 2) ||d_i||.
  double margin_ratio = 0.4;
  double spacing = 0.05;           ///< m between recorded path points
  int capacity = 4096;             ///< points of the path kept
  double retrace_width = 0.5;      ///< m: a target this close to its path, behind, is retracing it
  double natural_frequency = 2.0;  ///< omega_r (rad/s): how fast r follows the goal
  double damping = 1.0;            ///< zeta_r
  double max_acceleration = 5.0;   ///< ||r''|| bound (m/s^2)
  /// a_b (m/s^2): the braking the barrier (C5) plans with, at most max_acceleration.
  double braking_acceleration = 4.0;
  /// A (m/s^2): the hardest braking the barrier (C5) assumes of the target. In a chain of equal
  /// followers it is their max_acceleration, the hardest any of their references brakes.
  double target_braking = 5.0;
  /// m/s: how much faster than the target's own progress the goal may advance along the path
  /// (after it walked back, or on a new path), so that it never jumps forward.
  double catch_up_speed = 1.0;

  /// Throws ParameterError naming `<prefix>.gap_ratio` (not finite or < 1 + margin_ratio),
  /// `.margin_ratio` (not finite or < 0), `.spacing` (not finite or <= 0), `.capacity` (< 2 or >
  /// 2^20),
  /// `.retrace_width` (not finite or < 0), `.natural_frequency`, `.damping`,
  /// `.max_acceleration`, `.braking_acceleration`, `.target_braking`, `.catch_up_speed` (not
  /// finite or <= 0), and
  /// `.braking_acceleration` above `.max_acceleration`.
  void validate(const std::string& prefix) const;
};

/// One control tick of a convoy follower's reference (m, m/s, m/s^2; 3 entries, z 0 in 2-D).
struct ConvoySample {
  Eigen::Vector3d position = Eigen::Vector3d::Zero();      ///< r at the tick
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();      ///< r'
  Eigen::Vector3d acceleration = Eigen::Vector3d::Zero();  ///< r'', held over the period (C3)
  Eigen::Vector3d goal = Eigen::Vector3d::Zero();          ///< q = P(sigma*) (C2)
  double progress = 0.0;                                   ///< s, the target's arc length (m)
  double goal_arc = 0.0;                                   ///< sigma* (m)
  double chord = 0.0;    ///< ||p_target − r|| (m): the perimeter holds while >= ||d_i|| (C6)
  bool braking = false;  ///< the barrier (C5) bounded r'' at this tick
};

/// A convoy follower's reference, one control period T at a time:
///   (C2) sigma*_k = walkBack(min(s_k − g, sigma*_{k−1} + max(0, s_k − s_{k−1}) + c T),
///                            p_t, (1 + m) ||d||),  q = P(sigma*)   (m margin_ratio)
///        (c catch_up_speed: the goal never jumps forward along the path)
///   (C3) r''_0 = clamp_norm(omega^2 (q − r) + 2 zeta omega (q' − r'), a_max);
///        q' = (q_k − q_{k−1}) / T (r' at the first tick).
///   (C5) the stopping-distance barrier: n = (p_t − r) / c, c = ||p_t − r||, v_r = n . r',
///        v_t = n . v_t, h = c − c_min − max(v_r, 0)^2 / (2 a_b) + max(v_t, 0)^2 / (2 A); n . r''
///        is bounded by max(−a_max, a_b (omega h + min(0, v_t) − v_r) / max(v_r, a_b T)), the
///        rest of r''_0 kept within a_max.
///        r'' is held over T (or the interval to the next tick) and r, r' integrated exactly
///        with it: r is C^1, xi never jumps.
/// Allocates no memory after construction.
class ConvoyReference {
 public:
  /// @param parameters validated; @param period T (s) > 0
  /// @param separation_norm ||d_i|| (m) > 0: the arc gap is gap_ratio ||d_i||
  ConvoyReference(const ConvoyParameters& parameters, double period, double separation_norm);

  /// Starts with the target at @p target_position (m) moving at @p target_velocity (m/s), the
  /// path's initial direction @p direction (unit, from the slot to the target): r = q(0) and r'
  /// the target's velocity along the direction.
  void reset(const Eigen::Vector3d& target_position, const Eigen::Vector3d& target_velocity,
             const Eigen::Vector3d& direction);

  /// The sample one period T after the tick before (the first after reset(): at r(0)), the
  /// target at @p target_position (m) moving at @p target_velocity (m/s): tick(.., .., T).
  ConvoySample tick(const Eigen::Vector3d& target_position, const Eigen::Vector3d& target_velocity);
  /// The sample @p interval (s) after the tick before: r and r' first advance over it with the
  /// r'' of that tick held (C3); the goal's speed bound c and q' (C2), (C3) take the interval.
  /// An interval of 0 or less (or NaN) passes no time: the tick before's sample, unchanged.
  /// The barrier (C5) plans with T, so its guarantee holds for intervals up to T.
  ConvoySample tick(const Eigen::Vector3d& target_position, const Eigen::Vector3d& target_velocity,
                    double interval);

  const TargetPath& path() const { return path_; }
  double gap() const { return gap_; }
  double goalChord() const { return goal_chord_; }

 private:
  /// r'' (C3), (C5) at the current r, r'; @p braking set when the barrier bounds it.
  Eigen::Vector3d acceleration(const Eigen::Vector3d& goal, const Eigen::Vector3d& goal_velocity,
                               const Eigen::Vector3d& target_position,
                               const Eigen::Vector3d& target_velocity, bool known,
                               bool* braking) const;

  ConvoyParameters parameters_;
  double period_;
  double gap_;          ///< g (m)
  double goal_chord_;   ///< ||d|| + margin (m)
  double floor_chord_;  ///< c_min = ||d|| + margin / 2 (m)
  TargetPath path_;
  Eigen::Vector3d position_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d velocity_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d previous_goal_ = Eigen::Vector3d::Zero();
  double previous_progress_ = 0.0;
  double previous_goal_arc_ = 0.0;
  bool have_goal_ = false;
  ConvoySample last_sample_;  ///< the tick before's; its r'' is held until this tick
  bool have_sample_ = false;
};

/// The convoy's slot D = x_target − [r; r'] (m, m/s) of a k-axis double integrator (k = 2 or 3),
/// (C4): xi = x_target − x_i − D = [r − p_i; r' − v_i].
template <typename StateVector>
void convoySlotOffset(const StateVector& target_state, int axes, const ConvoySample& sample,
                      StateVector* offset) {
  *offset = target_state;
  for (int j = 0; j < axes; ++j) {
    (*offset)(j) -= sample.position(j);
    (*offset)(axes + j) -= sample.velocity(j);
  }
}

/// The convoy's known input u_r = r'' (m/s^2), (C4): with u_i = G y + u_a + u_r (no shared
/// target acceleration), xi' = A_c xi − B u_a.
template <typename InputVector>
void convoySlotAcceleration(const ConvoySample& sample, int axes, InputVector* acceleration) {
  acceleration->setZero(axes);
  for (int j = 0; j < axes; ++j) {
    (*acceleration)(j) = sample.acceleration(j);
  }
}

}  // namespace projection_collision_avoidance
