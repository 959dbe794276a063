#pragma once

/// @file
/// Protection from every sensed agent (doc/math.md, "Neighbours", (N1)-(N3)): a barrier on the
/// distance to each neighbour, turned into a half-space of the follower's command, and the
/// command projected onto the intersection of those half-spaces and the acceleration limit.

#include <array>
#include <limits>
#include <string>

#include <Eigen/Core>

#include "projection_collision_avoidance/core/CommandProjection.hpp"

namespace projection_collision_avoidance {

/// formation.neighbours: how a follower keeps out of the perimeters of the agents it senses: its
/// neighbours and, as a backstop for when the paper's assumptions fail (a push it cannot
/// answer), its own target.
struct NeighbourParameters {
  bool enabled = false;  ///< the section is given
  /// m: agents farther than this are not sensed; infinity: every agent
  double radius = std::numeric_limits<double>::infinity();
  /// rho (m), > 0: the perimeter kept around each neighbour; NaN: alpha ||d|| of the scenario
  double perimeter = std::numeric_limits<double>::quiet_NaN();
  double braking_acceleration = 1.0;  ///< a_b (m/s^2), > 0: what the barrier brakes with
  double neighbour_acceleration =
      0.0;                 ///< A_n (m/s^2), >= 0: a neighbour's, toward it, allowed for
  double rate = 2.0;       ///< omega (1/s), > 0: how fast h may fall toward 0
  int max_neighbours = 8;  ///< the most urgent ones kept, 1 .. 32

  /// Throws ParameterError naming formation.neighbours.<key> for a value out of range, and
  /// formation.neighbours.braking_acceleration when a_b + A_n exceeds @p acceleration_limit
  /// (m/s^2): the barrier could then ask more than the vehicle gives.
  void validate(double acceleration_limit) const;
};

/// One neighbour's constraint on the command: g^T u >= b, and the barrier's value.
struct NeighbourConstraint {
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();  ///< g = n, the unit vector from j to i
  double bound = 0.0;                                ///< b (m/s^2)
  double barrier = 0.0;   ///< h (m/s), (N1); -infinity inside the perimeter
  double distance = 0.0;  ///< c = ||p_i - p_j|| (m)
  /// Which neighbour it is: the number of NeighbourConstraints::add() calls before its own since
  /// clear() (0-based); -1 from neighbourBarrier() alone.
  int source = -1;
};

/// (N1)-(N2): the barrier of follower i against neighbour j and the half-space it puts its
/// command in. With p = p_i - p_j, v = v_i - v_j, c = ||p||, n = p / c, s = -n^T v (closing
/// speed), v_perp^2 = ||v||^2 - (n^T v)^2:
///   (N1)  h = sqrt(2 a_b (c - rho)) - s                                      (c > rho)
///   (N2)  n^T u_i >= b = a_b s / sqrt(2 a_b (c - rho)) - v_perp^2 / c + A_n - omega h
///         n^T u_i >= b = a_b + A_n                                           (c <= rho)
/// @param relative_position p (m), @param relative_velocity v (m/s), first k entries used
/// @param perimeter rho (m)
/// @return the constraint; for p = 0 the normal is the x axis (any direction pushes apart)
NeighbourConstraint neighbourBarrier(const Eigen::Vector3d& relative_position,
                                     const Eigen::Vector3d& relative_velocity,
                                     const NeighbourParameters& parameters, double perimeter);

/// (N3): the neighbours' half-spaces of one tick, most urgent first, for FollowerController
/// (StepInputs::command_constraints). Senses the agents within the radius, keeps the
/// max_neighbours of smallest h (inside the perimeter first, by distance), and leaves out a
/// half-space no command within the acceleration limit can violate (b <= -a_max). Fixed
/// capacity; allocates nothing.
class NeighbourConstraints {
 public:
  /// @param parameters validated, @param perimeter rho (m), @param dimension k = 1, 2 or 3
  /// @param acceleration_limit a_max (m/s^2), > 0 or infinity
  NeighbourConstraints(const NeighbourParameters& parameters, double perimeter, int dimension,
                       double acceleration_limit);

  /// Forgets the previous tick's neighbours.
  void clear();
  /// Neighbour j at p_i - p_j and v_i - v_j (first k entries; m, m/s); a non-finite one is
  /// counted (rejected()) and left out.
  void add(const Eigen::Vector3d& relative_position, const Eigen::Vector3d& relative_velocity) {
    add(relative_position, relative_velocity, perimeter_);
  }
  /// The same with a perimeter of its own, @p perimeter (m; the target's alpha ||d_i||).
  void add(const Eigen::Vector3d& relative_position, const Eigen::Vector3d& relative_velocity,
           double perimeter);
  /// The half-spaces of the kept neighbours in priority order.
  const CommandProjection& projection();
  /// Kept constraint @p j, 0 <= j < kept(), in priority order (most urgent first).
  const NeighbourConstraint& constraint(int j) const { return kept_[static_cast<std::size_t>(j)]; }

  int sensed() const { return sensed_; }      ///< neighbours within the radius this tick
  int kept() const { return count_; }         ///< of them, constraining (at most max_neighbours)
  int rejected() const { return rejected_; }  ///< non-finite neighbours this tick
  /// The smallest h this tick (m/s; -infinity: one inside the perimeter; infinity: none)
  double smallestBarrier() const;
  /// The smallest distance c to a sensed neighbour this tick (m; infinity: none)
  double nearest() const { return nearest_; }
  double perimeter() const { return perimeter_; }  ///< rho (m)

 private:
  static constexpr int kCapacity = CommandProjection::kMaxConstraints;
  NeighbourParameters parameters_;
  double perimeter_;
  double acceleration_limit_;
  std::array<NeighbourConstraint, kCapacity> kept_;  // sorted, most urgent first
  CommandProjection projection_;
  int count_ = 0;
  int added_ = 0;  // add() calls since clear()
  int sensed_ = 0;
  int rejected_ = 0;
  double nearest_ = std::numeric_limits<double>::infinity();
};

}  // namespace projection_collision_avoidance
