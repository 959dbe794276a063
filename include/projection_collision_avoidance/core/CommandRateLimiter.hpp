#pragma once

#include <algorithm>
#include <limits>

#include <Eigen/Core>

#include "projection_collision_avoidance/core/BallConstraint.hpp"

namespace projection_collision_avoidance {

/// Rate limit u(k) = u(k-1) + clamp(u* - u(k-1), r T): ||u(k) - u(k-1)|| <= r T (r in m/s^3,
/// T in s, u in m/s^2 for double integrators), as ros_controllers' SpeedLimiter limits a speed.
/// A step that comes less than a period after the previous one (Delta t = f T, f < 1) may change
/// the command by r T f = r Delta t only, so that the limit holds per second, not per step.
///
/// The limited command lies on the segment from the previous command u(k-1) to the target u*.
/// When both are in the ball ||u|| <= a (the saturation), so is the segment, the ball being
/// convex: the rate limit keeps the acceleration limit. Rounding is removed by moving the result
/// toward u(k-1) until euclideanNorm(u(k) - u(k-1)) <= r T and euclideanNorm(u(k)) <= a hold as
/// computed. The previous command starts at zero (a vehicle at rest). No step allocates memory.
template <typename Vector>
class CommandRateLimiter {
 public:
  /// @param jerk_limit r (m/s^3 for double integrators), > 0; infinity: no limit
  /// @param period T (s), > 0
  /// @param radius a, the bound ||u|| <= a that every command given to limit() keeps (m/s^2);
  ///        infinity: none
  /// @param size entries of the command
  CommandRateLimiter(double jerk_limit, double period, double radius, Eigen::Index size)
      : max_change_(jerk_limit * period), radius_(radius), previous_(Vector::Zero(size)) {}

  /// Limits the finite @p command (with euclideanNorm(command) <= radius) in place to the ball
  /// of radius r T f around the previous command, and makes the result the previous command.
  /// @param fraction f, the part of a period T since the previous command (Delta t / T, so that
  ///        the change is at most r Delta t): 1 or more (the default) allows r T, exactly the
  ///        limit of a whole period; 0, less, or NaN allows no change (the command is held)
  /// @return true if the command was changed
  bool limit(Vector& command, double fraction = 1.0) {
    if (!(max_change_ < std::numeric_limits<double>::infinity())) {
      previous_ = command;
      return false;
    }
    const double max_change = maxChange(fraction);
    Vector change = command - previous_;
    if (change.allFinite()) {
      if (!(clampNorm(change, max_change) > 0.0)) {
        previous_ = command;
        return false;
      }
    } else {  // the difference overflows, so it exceeds r T: only its direction is used
      change = 0.5 * command - 0.5 * previous_;
      change /= change.cwiseAbs().maxCoeff();
      change /= euclideanNorm(change);
      change *= max_change;
    }
    command = previous_ + change;
    // Rounding can leave the sum an ulp or so outside either ball: shorten the change by a
    // factor whose distance from 1 doubles each time. A zero change gives u(k-1), inside both.
    double shrink = 2.0 * std::numeric_limits<double>::epsilon();
    while (!command.allFinite() || euclideanNorm(command - previous_) > max_change ||
           euclideanNorm(command) > radius_) {
      change *= 1.0 - shrink;
      shrink = std::min(2.0 * shrink, 0.5);
      command = previous_ + change;
    }
    previous_ = command;
    return true;
  }

  /// Sets the previous command to @p command moved into the ball ||u|| <= radius (scaled along
  /// itself; zero if not finite), for example to carry it over to a new design.
  void setPrevious(const Vector& command) {
    previous_ = command;
    if (!previous_.allFinite()) {
      previous_.setZero();
    }
    clampNorm(previous_, radius_);
  }

  /// Back to rest: the previous command is zero.
  void reset() { previous_.setZero(); }

  /// The command the next limit() starts from (m/s^2 for double integrators).
  const Vector& previous() const { return previous_; }

  /// r T, the largest change per period (m/s^2 for double integrators); infinity: no limit.
  double maxChange() const { return max_change_; }

  /// r T f, the largest change limit() allows for the fraction @p fraction of a period (as
  /// limit() reads it: at most r T, 0 for f <= 0 or NaN); infinity: no limit.
  double maxChange(double fraction) const {
    if (fraction >= 1.0) {
      return max_change_;
    }
    return fraction > 0.0 ? max_change_ * fraction : 0.0;
  }

 private:
  double max_change_;
  double radius_;
  Vector previous_;
};

}  // namespace projection_collision_avoidance
