#pragma once

/// @file
/// Exact Euclidean projection of a command onto a ball intersected with half-spaces, in 1, 2 or
/// 3 dimensions, with a fallback by priority when the intersection is empty. Pure math: the
/// quantities carry whatever unit the caller gives them (the command and a_max the same one).

#include <array>
#include <cstdint>

#include <Eigen/Core>

namespace projection_collision_avoidance {

/// What CommandProjection::project() returns.
struct CommandProjectionResult {
  /// u*: the first m entries are the projection, the others are zero.
  Eigen::Vector3d command = Eigen::Vector3d::Zero();
  /// true unless u* is u_nom bit for bit (u_nom was feasible).
  bool changed = false;
  /// Kept half-spaces that hold with equality at u* (within the feasibility tolerance).
  int active = 0;
  /// Bit j set: half-space j is one of the active ones.
  std::uint32_t active_mask = 0;
  /// true when ||u*|| = a_max (within the feasibility tolerance); never for a_max = infinity.
  bool ball_active = false;
  /// Half-spaces dropped by the fallback (0 when the whole set is non-empty).
  int dropped = 0;
  /// Bit j set: half-space j was dropped.
  std::uint32_t dropped_mask = 0;
};

/// Solves
///   u* = argmin ||u - u_nom||^2  subject to  g_j^T u >= b_j (j = 0..n-1),  ||u|| <= a_max,
/// with u, u_nom, g_j in R^m (m = 1, 2 or 3), exactly up to rounding, by enumerating the
/// Karush-Kuhn-Tucker active sets: at the optimum at most m constraints with linearly independent
/// gradients carry the multipliers, so u* is u_nom, the projection of u_nom onto the affine set of
/// at most m planes g_j^T u = b_j, or the point nearest u_nom of the sphere ||u|| = a_max cut by
/// at most m - 1 of those planes (a circle or two points). The feasible candidate nearest u_nom
/// is u*.
///
/// The half-spaces are added in priority order (index 0 the most important) and processed in it:
/// the ball is always kept; half-space j is kept when the ball and the half-spaces kept before it
/// still intersect it, and dropped otherwise; u* is the projection onto the ball and the kept
/// half-spaces. When the whole set is non-empty nothing is dropped and u* is its projection. When
/// the projection x onto the ball and the half-spaces kept before j satisfies half-space j, x is
/// also the projection with j added; otherwise the new projection lies on the plane of j, and only
/// the active sets that contain j are enumerated (at most 1 + 31 + 465 for 32 half-spaces), by
/// size, skipping the supersets of a set whose affine set is already farther from u_nom than the
/// best feasible candidate. With 32 random half-spaces in 3-D a projection took about 0.1 ms
/// (0.3 ms at most) on a 2-core x86-64 machine.
///
/// Tolerances (relative; tol = kFeasibilityTolerance = 1e-9): with s the largest of ||u_nom||,
/// a_max (when finite), the norm of the point tested and |b_i| / ||g_i|| over the planes it was
/// computed from, the point is feasible when ||u|| <= a_max + tol s and every kept half-space has
/// g_j^T u >= b_j - tol max(s, |b_j| / ||g_j||) ||g_j|| (a far half-space does not loosen the
/// others). Rounding errors of the candidates are about 1e-16 s times the conditioning of their
/// planes; the same tolerance decides that a plane holds with equality (active).
/// Normals whose component orthogonal to the span of the others is below kIndependenceTolerance
/// times their norm (1e-10, the sine of the angle) count as dependent, and their set is skipped:
/// the candidate of a subset then violates the dropped plane by at most 1e-10 times its distance,
/// inside the feasibility tolerance. Where active planes meet at a small angle theta (more
/// generally: their unit normals have a small singular value theta), the result may lie about
/// kFeasibilityTolerance s / theta from the exact one (so does the exact one when the b_j change
/// by that tolerance); the tolerance also keeps such sets from being found empty by rounding.
/// u_nom counts as feasible (and is returned as is) when ||u_nom|| <= a_max exactly and the
/// half-spaces hold within the tolerance. The returned command always satisfies ||u*|| <= a_max
/// as computed (euclideanNorm()), the ball being a physical limit.
///
/// Fixed capacity: nothing is allocated after construction, project() allocates nothing.
class CommandProjection {
 public:
  /// Most half-spaces one problem holds.
  static constexpr int kMaxConstraints = 32;
  /// Relative feasibility tolerance (see the class comment).
  static constexpr double kFeasibilityTolerance = 1e-9;
  /// Sine of the angle below which a normal counts as in the span of others.
  static constexpr double kIndependenceTolerance = 1e-10;

  /// An empty problem.
  /// @param dimension m, the size of the command: 1, 2 or 3
  /// @throws std::invalid_argument for any other dimension
  explicit CommandProjection(int dimension);

  /// m, the size of the command.
  int dimension() const { return dimension_; }
  /// Half-spaces held, n.
  int size() const { return count_; }

  /// Removes every half-space.
  void clear() { count_ = 0; }

  /// Appends the half-space g^T u >= b with the lowest priority so far (index size()).
  /// @param normal g; only the first m entries are used (the others are ignored)
  /// @param bound b
  /// @return false, and the half-space is ignored, when the problem is full
  ///         (kMaxConstraints), or g (first m entries) or b is not finite, or g is zero
  bool add(const Eigen::Vector3d& normal, double bound);

  /// The projection of @p nominal onto the ball and the half-spaces (dropping half-spaces by
  /// priority when they do not intersect, see the class comment). A nominal command that is
  /// feasible is returned bit for bit (changed = false).
  /// @param nominal u_nom; only the first m entries are used
  /// @param max_norm a_max, the radius of the ball ||u|| <= a_max: > 0, or infinity for no ball
  /// @throws std::invalid_argument when u_nom (first m entries) is not finite or max_norm is not
  ///         positive (or NaN)
  CommandProjectionResult project(const Eigen::Vector3d& nominal, double max_norm) const;

 private:
  int dimension_;
  int count_ = 0;
  /// g_j / ||g_j|| (entries beyond m zero).
  std::array<Eigen::Vector3d, kMaxConstraints> normals_;
  /// b_j / ||g_j||: the half-space is normals_[j]^T u >= offsets_[j].
  std::array<double, kMaxConstraints> offsets_;
};

}  // namespace projection_collision_avoidance
