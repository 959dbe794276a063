#include "projection_collision_avoidance/core/SafetyFilter.hpp"

#include <cmath>

#include "projection_collision_avoidance/core/BallConstraint.hpp"
#include "projection_collision_avoidance/core/ParameterError.hpp"

namespace projection_collision_avoidance {

void SafetyFilterParameters::validate(const std::string& prefix) const {
  if (!(rate > 0.0) || !std::isfinite(rate)) {
    throw ParameterError(prefix + ".rate",
                         "must be finite and > 0 (1/s), got " + std::to_string(rate));
  }
}

BarrierConstraint exponentialBarrier(const Eigen::Vector3d& relative_position,
                                     const Eigen::Vector3d& relative_velocity,
                                     const Eigen::Vector3d& other_acceleration, double perimeter,
                                     double rate) {
  const Eigen::Vector3d& p = relative_position;
  const Eigen::Vector3d& v = relative_velocity;
  BarrierConstraint c;
  c.normal = p;
  c.barrier = p.squaredNorm() - perimeter * perimeter;  // (B1)
  c.barrier_rate = 2.0 * p.dot(v);
  // (B2): h'' + 2 lambda h' + lambda^2 h >= 0 with h'' = 2 ||v||^2 + 2 p^T (u_i - a_j), halved.
  c.bound = p.dot(other_acceleration) - v.squaredNorm() - rate * c.barrier_rate -
            0.5 * rate * rate * c.barrier;
  return c;
}

Eigen::Vector3d singleBarrierCommand(const Eigen::Vector3d& nominal, const Eigen::Vector3d& normal,
                                     double bound) {
  const double norm2 = normal.squaredNorm();
  const double shortfall = bound - normal.dot(nominal);
  if (!(norm2 > 0.0) || !(shortfall > 0.0)) {
    return nominal;
  }
  return nominal + (shortfall / norm2) * normal;  // (B3), one barrier
}

namespace {

/// The command of norm @p limit (m/s^2) along the nonzero finite @p direction, at any scale of
/// it: normalised by its largest entry first, so that neither its norm overflows nor its square
/// underflows, and clamped so that rounding leaves euclideanNorm() <= limit.
Eigen::Vector3d bestEffort(const Eigen::Vector3d& direction, double limit) {
  Eigen::Vector3d u = direction / direction.cwiseAbs().maxCoeff();
  u /= euclideanNorm(u);
  u *= limit;
  clampNorm(u, limit);
  return u;
}

}  // namespace

SafetyFilter::SafetyFilter(int dimension) : qp_(dimension) {}

void SafetyFilter::clear() { qp_.clear(); }

bool SafetyFilter::add(const BarrierConstraint& constraint) {
  const bool first = qp_.size() == 0;
  if (!qp_.add(constraint.normal, constraint.bound)) {
    return false;
  }
  if (first) {
    first_normal_ = constraint.normal;
    first_normal_.tail(3 - qp_.dimension()).setZero();
  }
  return true;
}

SafetyFilterResult SafetyFilter::filter(const Eigen::Vector3d& nominal,
                                        double acceleration_limit) const {
  const int k = qp_.dimension();
  SafetyFilterResult result;
  Eigen::Vector3d u = Eigen::Vector3d::Zero();
  u.head(k) = nominal.head(k);
  const CommandProjectionResult qp = qp_.project(u, acceleration_limit);
  result.command = qp.command;
  result.changed = qp.changed;
  result.active_count = qp.active;
  result.limit_active = qp.ball_active;
  result.dropped = qp.dropped;
  result.infeasible = qp.dropped > 0;
  for (int j = 0; j < qp_.size(); ++j) {  // the most urgent active barrier
    if (((qp.active_mask >> j) & 1U) != 0U) {
      result.active = j;
      break;
    }
  }
  // The most urgent barrier dropped: alone it is out of reach within the limit (the ball is
  // always kept). Its best effort, the command of the limit's norm along g_0; a nominal command
  // already that one within the QP's tolerance (saturated along g_0) is kept as it is.
  if ((qp.dropped_mask & 1U) != 0U) {
    const Eigen::Vector3d best = bestEffort(first_normal_, acceleration_limit);
    result.changed =
        euclideanNorm(best - u) > CommandProjection::kFeasibilityTolerance * acceleration_limit;
    result.command = result.changed ? best : u;
    result.active = -1;
    result.active_count = 0;
    result.limit_active = true;
  }
  return result;
}

}  // namespace projection_collision_avoidance
