#pragma once

/// @file
/// The control barrier function safety filter (CBF-QP) the package is compared with
/// (doc/math.md, "A control barrier function filter", (B1)-(B3)): an exponential barrier of
/// relative degree two on the distance to each sensed agent, each a half-space of the follower's
/// command, and the nominal command projected onto their intersection with the acceleration
/// limit ||u|| <= a_max. Pure math: Eigen and std only.

#include <string>

#include <Eigen/Core>

#include "projection_collision_avoidance/core/CommandProjection.hpp"

namespace projection_collision_avoidance {

/// controller.safety_filter: the exponential barrier's gains, from one double pole.
struct SafetyFilterParameters {
  /// lambda (1/s), > 0: the double pole of (B2), k_1 = 2 lambda and k_0 = lambda^2; how fast the
  /// barrier lets h and h' + lambda h fall toward 0.
  double rate = 2.0;
  /// Throws ParameterError naming `<prefix>.rate` when it is not finite or not positive.
  void validate(const std::string& prefix) const;
};

/// One agent's barrier (B1) and the half-space (B2) it puts the follower's command in.
struct BarrierConstraint {
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();  ///< g = p = p_i − p_j (m)
  double bound = 0.0;                                ///< b (m^2/s^2): g^T u_i >= b
  double barrier = 0.0;                              ///< h = ||p||^2 − rho^2 (m^2)
  double barrier_rate = 0.0;                         ///< h' = 2 p^T v (m^2/s)
};

/// (B1), (B2): the exponential barrier of follower i against agent j. With p = p_i − p_j and
/// v = v_i − v_j (m, m/s), a_j agent j's acceleration (m/s^2; 0 when unknown) and rho the
/// perimeter (m):
///   (B1)  h = ||p||^2 − rho^2,   h' = 2 p^T v,   h'' = 2 ||v||^2 + 2 p^T (u_i − a_j)
///   (B2)  h'' + 2 lambda h' + lambda^2 h >= 0
///         <=>  p^T u_i >= b = p^T a_j − ||v||^2 − 2 lambda p^T v − (lambda^2 / 2) h
/// In 1-D and 2-D the entries beyond the command's size are 0.
BarrierConstraint exponentialBarrier(const Eigen::Vector3d& relative_position,
                                     const Eigen::Vector3d& relative_velocity,
                                     const Eigen::Vector3d& other_acceleration, double perimeter,
                                     double rate);

/// (B3) with one barrier and no acceleration limit, the CBF-QP's closed form:
///   u* = u_nom + max(0, b − g^T u_nom) / ||g||^2 g   (u_nom for g = 0)
Eigen::Vector3d singleBarrierCommand(const Eigen::Vector3d& nominal, const Eigen::Vector3d& normal,
                                     double bound);

/// What SafetyFilter::filter() returns.
struct SafetyFilterResult {
  Eigen::Vector3d command = Eigen::Vector3d::Zero();  ///< u* (m/s^2), first k entries
  bool changed = false;                               ///< u* differs from u_nom
  int active = -1;            ///< the most urgent barrier holding with equality at u*, or −1
  int active_count = 0;       ///< barriers holding with equality at u*
  bool limit_active = false;  ///< ||u*|| = a_max
  bool infeasible = false;    ///< the barriers and the limit could not all be met
  int dropped = 0;            ///< barriers left out (infeasible)
};

/// (B3): u* = argmin ||u − u_nom||^2 s.t. (B2) for every barrier added, ||u|| <= a_max, solved
/// exactly (CommandProjection). The barriers are added in priority order, the most urgent first.
/// When they and the limit cannot all be met (infeasible: the limit always holds, it is
/// physical): if the most urgent barrier alone cannot be met within the limit, u* = a_max g_0 /
/// ||g_0||, the command that comes nearest to meeting it; else the less urgent barriers that do
/// not fit are left out, in priority order (CommandProjection's fallback). Fixed capacity
/// (CommandProjection::kMaxConstraints barriers); allocates nothing.
class SafetyFilter {
 public:
  /// @param dimension k, the size of the command: 1, 2 or 3
  explicit SafetyFilter(int dimension);
  /// Forgets the barriers of the step before.
  void clear();
  /// Adds a barrier with the lowest priority so far; false when it is ignored (the filter is
  /// full, or it is not finite, or g = 0: the agents coincide, no direction is known).
  bool add(const BarrierConstraint& constraint);
  /// Barriers held.
  int size() const { return qp_.size(); }
  /// u* for @p nominal (first k entries, finite) and a_max = @p acceleration_limit (> 0 or
  /// infinity).
  SafetyFilterResult filter(const Eigen::Vector3d& nominal, double acceleration_limit) const;
  /// The QP of the barriers added (their half-spaces, unit normals).
  const CommandProjection& problem() const { return qp_; }

 private:
  CommandProjection qp_;
  Eigen::Vector3d first_normal_ = Eigen::Vector3d::Zero();  ///< g_0
};

}  // namespace projection_collision_avoidance
