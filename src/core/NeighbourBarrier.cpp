#include "projection_collision_avoidance/core/NeighbourBarrier.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "projection_collision_avoidance/core/ParameterError.hpp"

namespace projection_collision_avoidance {
namespace {

const std::string kNeighbourKey = "formation.neighbours.";

void requireAbove(const std::string& name, double value, double low, bool allow_infinity) {
  if (!(value > low) || (!allow_infinity && !std::isfinite(value))) {
    throw ParameterError(kNeighbourKey + name,
                         "must be " + std::string(allow_infinity ? "" : "finite and ") + "> " +
                             std::to_string(low) + ", got " + std::to_string(value));
  }
}

/// Whether @p a is more urgent than @p b: smaller h, then nearer.
bool moreUrgent(const NeighbourConstraint& a, const NeighbourConstraint& b) {
  if (a.barrier != b.barrier) {
    return a.barrier < b.barrier;
  }
  return a.distance < b.distance;
}

}  // namespace

void NeighbourParameters::validate(double acceleration_limit) const {
  if (!enabled) {
    return;
  }
  requireAbove("radius", radius, 0.0, true);
  if (!std::isnan(perimeter)) {
    requireAbove("perimeter", perimeter, 0.0, false);
  }
  requireAbove("braking_acceleration", braking_acceleration, 0.0, false);
  if (!(neighbour_acceleration >= 0.0) || !std::isfinite(neighbour_acceleration)) {
    throw ParameterError(kNeighbourKey + "neighbour_acceleration",
                         "must be finite and >= 0, got " + std::to_string(neighbour_acceleration));
  }
  requireAbove("rate", rate, 0.0, false);
  if (max_neighbours < 1 || max_neighbours > CommandProjection::kMaxConstraints) {
    throw ParameterError(kNeighbourKey + "max_neighbours",
                         "must lie in 1 .. 32, got " + std::to_string(max_neighbours));
  }
  if (braking_acceleration + neighbour_acceleration > acceleration_limit) {
    throw ParameterError(kNeighbourKey + "braking_acceleration",
                         "plus neighbour_acceleration (" +
                             std::to_string(braking_acceleration + neighbour_acceleration) +
                             " m/s^2) exceeds controller.acceleration_limit (" +
                             std::to_string(acceleration_limit) +
                             " m/s^2): the barrier could ask more than the vehicle gives");
  }
}

NeighbourConstraint neighbourBarrier(const Eigen::Vector3d& relative_position,
                                     const Eigen::Vector3d& relative_velocity,
                                     const NeighbourParameters& parameters, double perimeter) {
  NeighbourConstraint constraint;
  const double a_b = parameters.braking_acceleration;
  const double c = relative_position.norm();
  constraint.distance = c;
  constraint.normal = c > 0.0 ? Eigen::Vector3d(relative_position / c) : Eigen::Vector3d::UnitX();
  const double room = c - perimeter;  // c - rho
  const double stopping_speed = std::sqrt(2.0 * a_b * std::max(0.0, room));
  if (!(stopping_speed > 0.0)) {  // (N2), c <= rho: push apart
    constraint.barrier = -std::numeric_limits<double>::infinity();
    constraint.bound = a_b + parameters.neighbour_acceleration;
    return constraint;
  }
  const double along = constraint.normal.dot(relative_velocity);  // n^T v
  const double closing = -along;                                  // s
  const double across = std::max(0.0, relative_velocity.squaredNorm() - along * along);
  constraint.barrier = stopping_speed - closing;  // (N1)
  constraint.bound = a_b * closing / stopping_speed - across / c +
                     parameters.neighbour_acceleration - parameters.rate * constraint.barrier;
  return constraint;
}

NeighbourConstraints::NeighbourConstraints(const NeighbourParameters& parameters, double perimeter,
                                           int dimension, double acceleration_limit)
    : parameters_(parameters),
      perimeter_(perimeter),
      acceleration_limit_(acceleration_limit),
      projection_(dimension) {}

void NeighbourConstraints::clear() {
  count_ = 0;
  added_ = 0;
  sensed_ = 0;
  rejected_ = 0;
  nearest_ = std::numeric_limits<double>::infinity();
}

void NeighbourConstraints::add(const Eigen::Vector3d& relative_position,
                               const Eigen::Vector3d& relative_velocity, double perimeter) {
  const int source = added_++;
  const int k = projection_.dimension();
  Eigen::Vector3d p = Eigen::Vector3d::Zero();
  Eigen::Vector3d v = Eigen::Vector3d::Zero();
  p.head(k) = relative_position.head(k);
  v.head(k) = relative_velocity.head(k);
  if (!p.allFinite() || !v.allFinite()) {
    ++rejected_;
    return;
  }
  const double distance = p.norm();
  if (!(distance <= parameters_.radius)) {
    return;
  }
  ++sensed_;
  nearest_ = std::min(nearest_, distance);
  NeighbourConstraint constraint = neighbourBarrier(p, v, parameters_, perimeter);
  constraint.source = source;
  if (!(constraint.bound > -acceleration_limit_) || !std::isfinite(constraint.bound)) {
    return;  // no command within the limit violates it (or it overflowed: not kept)
  }
  const int capacity = parameters_.max_neighbours;
  if (count_ == capacity && !moreUrgent(constraint, kept_[static_cast<std::size_t>(count_ - 1)])) {
    return;
  }
  int at = std::min(count_, capacity - 1);  // insertion, the least urgent falls off when full
  while (at > 0 && moreUrgent(constraint, kept_[static_cast<std::size_t>(at - 1)])) {
    kept_[static_cast<std::size_t>(at)] = kept_[static_cast<std::size_t>(at - 1)];
    --at;
  }
  kept_[static_cast<std::size_t>(at)] = constraint;
  count_ = std::min(count_ + 1, capacity);
}

const CommandProjection& NeighbourConstraints::projection() {
  projection_.clear();
  for (int j = 0; j < count_; ++j) {
    projection_.add(kept_[static_cast<std::size_t>(j)].normal,
                    kept_[static_cast<std::size_t>(j)].bound);
  }
  return projection_;
}

double NeighbourConstraints::smallestBarrier() const {
  return count_ > 0 ? kept_[0].barrier : std::numeric_limits<double>::infinity();
}

}  // namespace projection_collision_avoidance
