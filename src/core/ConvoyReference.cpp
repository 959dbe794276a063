#include "projection_collision_avoidance/core/ConvoyReference.hpp"

#include <algorithm>
#include <cmath>

#include "projection_collision_avoidance/core/ParameterError.hpp"

namespace projection_collision_avoidance {
namespace {

constexpr int kMaxCapacity = 1 << 20;

void requireAtLeast(double value, double bound, bool strict, const std::string& key) {
  if (!std::isfinite(value) || value < bound || (strict && value == bound)) {
    throw ParameterError(key, std::string("must be finite and ") + (strict ? "> " : ">= ") +
                                  std::to_string(bound) + ", got " + std::to_string(value));
  }
}

/// Scales @p vector down to norm @p limit when longer.
void clampNorm(double limit, Eigen::Vector3d* vector) {
  const double norm = vector->norm();
  if (norm > limit) {
    *vector *= limit / norm;
  }
}

}  // namespace

void ConvoyParameters::validate(const std::string& prefix) const {
  requireAtLeast(margin_ratio, 0.0, false, prefix + ".margin_ratio");
  requireAtLeast(gap_ratio, 1.0 + margin_ratio, false, prefix + ".gap_ratio");
  requireAtLeast(spacing, 0.0, true, prefix + ".spacing");
  if (capacity < 2 || capacity > kMaxCapacity) {
    throw ParameterError(prefix + ".capacity", "must lie in [2, " + std::to_string(kMaxCapacity) +
                                                   "] points, got " + std::to_string(capacity));
  }
  requireAtLeast(retrace_width, 0.0, false, prefix + ".retrace_width");
  requireAtLeast(natural_frequency, 0.0, true, prefix + ".natural_frequency");
  requireAtLeast(damping, 0.0, true, prefix + ".damping");
  requireAtLeast(max_acceleration, 0.0, true, prefix + ".max_acceleration");
  requireAtLeast(braking_acceleration, 0.0, true, prefix + ".braking_acceleration");
  requireAtLeast(target_braking, 0.0, true, prefix + ".target_braking");
  if (braking_acceleration > max_acceleration) {
    throw ParameterError(prefix + ".braking_acceleration",
                         "must not exceed max_acceleration (" + std::to_string(max_acceleration) +
                             "), got " + std::to_string(braking_acceleration));
  }
  requireAtLeast(catch_up_speed, 0.0, true, prefix + ".catch_up_speed");
}

ConvoyReference::ConvoyReference(const ConvoyParameters& parameters, double period,
                                 double separation_norm)
    : parameters_(parameters),
      period_(period),
      gap_(parameters.gap_ratio * separation_norm),
      goal_chord_((1.0 + parameters.margin_ratio) * separation_norm),
      floor_chord_((1.0 + 0.5 * parameters.margin_ratio) * separation_norm),
      path_(parameters.capacity, parameters.spacing, parameters.retrace_width) {}

void ConvoyReference::reset(const Eigen::Vector3d& target_position,
                            const Eigen::Vector3d& target_velocity,
                            const Eigen::Vector3d& direction) {
  path_.reset(target_position, direction);
  const double sigma = path_.walkBack(path_.progress() - gap_, target_position, goal_chord_);
  position_ = path_.at(sigma);
  previous_progress_ = path_.progress();
  previous_goal_arc_ = sigma;
  previous_goal_ = position_;
  const Eigen::Vector3d along = path_.at(1.0) - path_.at(0.0);  // the unit initial direction
  velocity_ = target_velocity.allFinite() ? Eigen::Vector3d(along * along.dot(target_velocity))
                                          : Eigen::Vector3d::Zero();
  have_goal_ = false;
  have_sample_ = false;
}

Eigen::Vector3d ConvoyReference::acceleration(const Eigen::Vector3d& goal,
                                              const Eigen::Vector3d& goal_velocity,
                                              const Eigen::Vector3d& target_position,
                                              const Eigen::Vector3d& target_velocity, bool known,
                                              bool* braking) const {
  // (C3): the pull toward the goal, omega^2 (q − r) + 2 zeta omega (q' − r') written as a speed
  // to reach, q' + (omega / (2 zeta)) (q − r), with the approach part at most c and the speed at
  // most ||v_t|| + c, so that the reference never runs away from a goal that jumps back along the
  // path or lies far ahead, nor outruns its target by more than c; the result's norm bounded.
  const double omega = parameters_.natural_frequency;
  const double limit = parameters_.max_acceleration;
  const double catch_up = parameters_.catch_up_speed;
  Eigen::Vector3d approach = omega / (2.0 * parameters_.damping) * (goal - position_);
  clampNorm(catch_up, &approach);
  Eigen::Vector3d speed = goal_velocity + approach;
  clampNorm((known ? target_velocity.norm() : 0.0) + catch_up, &speed);
  Eigen::Vector3d acceleration = 2.0 * parameters_.damping * omega * (speed - velocity_);
  if (!acceleration.allFinite()) {
    acceleration.setZero();
  }
  clampNorm(limit, &acceleration);
  *braking = false;
  const Eigen::Vector3d to_target = target_position - position_;
  const double chord = to_target.norm();
  if (!known || !(chord > 0.0)) {
    return acceleration;
  }
  // (C5): the stopping-distance barrier h = c − c_min − v_r^2 / (2 a_b) + v_t^2 / (2 A), kept
  // by n . r'' <= a_b (omega h + min(0, n . v_t) − n . r') / max(v_r, a_b T), at least −a_max.
  const Eigen::Vector3d along = to_target / chord;
  const double reference_speed = along.dot(velocity_);     // toward the target
  const double target_speed = along.dot(target_velocity);  // away from the reference
  const double braking_limit = parameters_.braking_acceleration;
  const double reference_stop = std::max(0.0, reference_speed);
  const double target_stop = std::max(0.0, target_speed);
  const double barrier = chord - floor_chord_ -
                         reference_stop * reference_stop / (2.0 * braking_limit) +
                         target_stop * target_stop / (2.0 * parameters_.target_braking);
  // The divisor v_r of the exact condition, kept off 0: at least a_b T where the bound brakes
  // (slack < 0), at least a_b / omega where it allows an approach (slack >= 0), so that a
  // reference at rest or backing off is not let run at the target in one tick.
  const double slack = omega * barrier + std::min(0.0, target_speed) - reference_speed;
  const double divisor =
      std::max(reference_stop, slack < 0.0 ? braking_limit * period_ : braking_limit / omega);
  const double bound = std::max(-limit, braking_limit * slack / divisor);
  const double normal = along.dot(acceleration);
  if (normal <= bound) {
    return acceleration;
  }
  *braking = true;
  Eigen::Vector3d tangential = acceleration - normal * along;
  const double room = std::sqrt(std::max(0.0, limit * limit - bound * bound));
  clampNorm(room, &tangential);
  return bound * along + tangential;
}

ConvoySample ConvoyReference::tick(const Eigen::Vector3d& target_position,
                                   const Eigen::Vector3d& target_velocity) {
  return tick(target_position, target_velocity, period_);
}

ConvoySample ConvoyReference::tick(const Eigen::Vector3d& target_position,
                                   const Eigen::Vector3d& target_velocity, double interval) {
  if (have_sample_) {
    if (!(interval > 0.0)) {
      return last_sample_;  // no time passed since the tick before: nothing new
    }
    // r'' held over the interval since the tick before, r and r' integrated exactly with it.
    position_ += interval * velocity_ + 0.5 * interval * interval * last_sample_.acceleration;
    velocity_ += interval * last_sample_.acceleration;
  }
  // A target position not known this tick (not finite) records nothing and the goal keeps its
  // arc and point (q' = 0): the reference comes to rest at the last goal. Without a finite
  // velocity too, the target is unknown to (C3)'s speed bound and to (C5).
  const bool known = target_position.allFinite() && target_velocity.allFinite();
  ConvoySample sample;
  Eigen::Vector3d goal_velocity = Eigen::Vector3d::Zero();
  if (target_position.allFinite()) {
    path_.record(target_position);
    double upper = path_.progress() - gap_;  // (C2)
    if (have_goal_) {
      upper = std::min(upper, previous_goal_arc_ +
                                  std::max(0.0, path_.progress() - previous_progress_) +
                                  parameters_.catch_up_speed * interval);
    }
    const double arc = path_.walkBack(upper, target_position, goal_chord_);
    const Eigen::Vector3d goal = path_.at(arc);
    goal_velocity = have_goal_ ? Eigen::Vector3d((goal - previous_goal_) / interval)
                               : Eigen::Vector3d(velocity_);
    previous_progress_ = path_.progress();
    previous_goal_arc_ = arc;
    previous_goal_ = goal;
    have_goal_ = true;
  }
  sample.progress = path_.progress();
  sample.goal_arc = previous_goal_arc_;
  sample.goal = previous_goal_;
  sample.position = position_;
  sample.velocity = velocity_;
  sample.acceleration = acceleration(sample.goal, goal_velocity, target_position, target_velocity,
                                     known, &sample.braking);
  sample.chord = known ? (target_position - position_).norm() : 0.0;
  last_sample_ = sample;
  have_sample_ = true;
  return sample;
}

}  // namespace projection_collision_avoidance
