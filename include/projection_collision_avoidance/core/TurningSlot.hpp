#pragma once

/// @file
/// Slots that turn with their target (doc/math.md, "Turning slots"): the slot d_i is given in
/// the target's body frame and turned by a slot heading theta(t) that follows the target's
/// heading psi(t) with a bounded yaw rate and yaw acceleration (T1). The follower's relative error
/// becomes xi = x_target - x_i - D(theta, theta') (T2), and the command adds the slot's own
/// acceleration u_r (T3), a known input, so that xi obeys the paper's relative dynamics. Off by
/// default (formation.slots: world): then the paper's laws are untouched.

#include <cmath>
#include <optional>
#include <string>

#include <Eigen/Core>

namespace projection_collision_avoidance {

/// The slot heading's generator (formation.turning), (T1).
struct SlotHeadingParameters {
  double natural_frequency = 1.0;     ///< omega_theta (rad/s): how fast theta follows psi
  double damping = 1.0;               ///< zeta_theta
  double max_yaw_rate = 0.5;          ///< |theta'| bound (rad/s)
  double max_yaw_acceleration = 0.5;  ///< |theta''| bound (rad/s^2)
  /// Below this target speed (m/s) the heading of a point-mass target (its velocity's direction)
  /// is undefined: theta stops turning (psi taken as theta, psi' as 0).
  double min_speed = 0.5;
  /// The target may drive backward: a heading more than pi/2 from theta is taken as the target
  /// reversing, psi + pi (the slot stays behind its body instead of swinging round it).
  bool reversing = false;

  /// Throws ParameterError naming `<prefix>.natural_frequency` (not finite or <= 0), `.damping`
  /// (not finite or <= 0), `.max_yaw_rate`, `.max_yaw_acceleration` (not finite or <= 0) or
  /// `.min_speed` (not finite or < 0).
  void validate(const std::string& prefix) const;
};

/// theta, theta' and theta'' of the slot heading at one control tick (rad, rad/s, rad/s^2).
struct SlotHeadingSample {
  double angle = 0.0;
  double rate = 0.0;
  double acceleration = 0.0;  ///< held over the period that starts at the tick
};

/// psi = atan2(v_y, v_x) of a target moving at (v_x, v_y) m/s; empty below @p min_speed (m/s) or
/// for a non-finite velocity: a point mass at rest has no heading.
std::optional<double> velocityHeading(double velocity_x, double velocity_y, double min_speed);

/// The angle in (-pi, pi] equal to @p angle modulo 2 pi (rad); NaN for a non-finite angle.
double wrapAngle(double angle);

/// The slot heading theta(t), (T1), one control period T at a time:
///   theta'' = clamp(omega^2 wrap(psi - theta) + 2 zeta omega (psi' - theta'), +-beta),
/// further limited so that |theta'| <= max_yaw_rate at the end of the period, held over the
/// period; theta and theta' integrated exactly with it. psi' is the difference of the two latest
/// headings over T (0 when either is missing). With reversing, psi is first replaced by psi + pi
/// when |wrap(psi - theta)| > pi/2 (a target driving backward). Without a heading (a target at
/// rest, a heading not finite) psi = theta and psi' = 0: theta stops turning. theta is continuous
/// and unwrapped; theta' is continuous. Allocates no memory.
class SlotHeading {
 public:
  /// @param parameters validated
  /// @param period T (s), > 0
  SlotHeading(const SlotHeadingParameters& parameters, double period);

  /// theta = @p angle (rad; 0 if not finite), theta' = 0, no previous heading.
  void reset(double angle);

  /// The sample at this tick, with theta'' planned from the target's heading @p heading (rad,
  /// empty: unknown); then theta and theta' advance to the next tick.
  SlotHeadingSample tick(std::optional<double> heading);

  /// theta and theta' of the next tick (rad, rad/s).
  double angle() const { return angle_; }
  double rate() const { return rate_; }

 private:
  SlotHeadingParameters parameters_;
  double period_;
  double angle_ = 0.0;
  double rate_ = 0.0;
  std::optional<double> previous_heading_;
};

/// The position part of a state vector x = [p; v] of a k-axis double integrator turned by
/// @p angle about the z axis: R(theta) p, in place. k = 2 or 3 (z kept).
template <typename Vector>
void rotateAboutZ(double angle, Vector* position) {
  const double c = std::cos(angle);
  const double s = std::sin(angle);
  const double x = (*position)(0);
  const double y = (*position)(1);
  (*position)(0) = c * x - s * y;
  (*position)(1) = s * x + c * y;
}

/// The turning slot's offset D (m, m/s), (T2):
///   D = [R(theta) d_p; theta' J R(theta) d_p],   J = [[0, -1], [1, 0]] in the x-y plane,
/// for the slot d = [d_p; 0] of a k-axis double integrator (k = 2 or 3, z not turned), given in
/// the target's body frame; xi = x_target - x_i - D. D(0, 0) = d.
/// @param separation d (2k entries, in ker A); @param sample theta, theta'; @param[out] offset
template <typename StateVector>
void turningSlotOffset(const StateVector& separation, int axes, const SlotHeadingSample& sample,
                       StateVector* offset) {
  *offset = separation;
  if constexpr (StateVector::SizeAtCompileTime != Eigen::Dynamic &&
                StateVector::SizeAtCompileTime < 4) {
    return;  // a 1-axis model has no plane to turn in (FormationSpec::validate() refuses it)
  }
  auto turned = offset->head(axes);
  rotateAboutZ(sample.angle, &turned);
  auto velocity = offset->tail(axes);
  velocity.setZero();
  velocity(0) = -sample.rate * turned(1);  // theta' J R d_p
  velocity(1) = sample.rate * turned(0);
}

/// The slot's own acceleration that the command adds, u_r (m/s^2), (T3):
///   u_r = -(d^2/dt^2)(R(theta) d_p) = -(theta'' J + theta'^2 J^2) R(theta) d_p,
/// so that with u_2 = G y + u_a + u_ff + u_r the error xi = x_target - x_i - D obeys the paper's
/// xi' = A_c xi - B u_a + B (a_target - u_ff) + u_d. J^2 = -I in the x-y plane, 0 on z.
/// @param separation d (2k entries); @param[out] acceleration k entries
template <typename StateVector, typename InputVector>
void turningSlotAcceleration(const StateVector& separation, int axes,
                             const SlotHeadingSample& sample, InputVector* acceleration) {
  acceleration->setZero(axes);
  if constexpr (InputVector::SizeAtCompileTime != Eigen::Dynamic &&
                InputVector::SizeAtCompileTime < 2) {
    return;  // a 1-axis model has no plane to turn in (FormationSpec::validate() refuses it)
  }
  const double c = std::cos(sample.angle);
  const double s = std::sin(sample.angle);
  const double x = c * separation(0) - s * separation(1);  // R(theta) d_p in the plane
  const double y = s * separation(0) + c * separation(1);
  const double squared_rate = sample.rate * sample.rate;
  (*acceleration)(0) = sample.acceleration * y + squared_rate * x;   // -(theta'' J) R d_p ...
  (*acceleration)(1) = -sample.acceleration * x + squared_rate * y;  // ... - theta'^2 J^2 R d_p
}

}  // namespace projection_collision_avoidance
