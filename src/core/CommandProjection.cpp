#include "projection_collision_avoidance/core/CommandProjection.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "projection_collision_avoidance/core/BallConstraint.hpp"

namespace projection_collision_avoidance {
namespace {

std::uint32_t bit(int j) { return std::uint32_t{1} << j; }

/// The affine set of up to three planes, Q^T u = z, with Q orthonormal (the planes' unit normals
/// orthonormalised in the order given, twice for accuracy): u = p0 + w with p0 = Q z, Q^T w = 0.
struct Frame {
  Eigen::Vector3d q[3];
  double z[3] = {0.0, 0.0, 0.0};
  int size = 0;
  double offsets = 0.0;  ///< the largest |c| of the planes
};

/// Adds the plane n^T u = c (n a unit vector) to @p frame.
/// @return false (frame unchanged) when n is within kIndependenceTolerance of the span of the
///         frame's normals
bool addPlane(Frame* frame, const Eigen::Vector3d& n, double c) {
  Eigen::Vector3d w = n;
  double rhs = c;
  for (int pass = 0; pass < 2; ++pass) {
    for (int l = 0; l < frame->size; ++l) {
      const double r = frame->q[l].dot(w);
      w -= r * frame->q[l];
      rhs -= r * frame->z[l];
    }
  }
  const double norm = w.norm();
  if (!(norm > CommandProjection::kIndependenceTolerance)) {
    return false;
  }
  frame->q[frame->size] = w / norm;
  frame->z[frame->size] = rhs / norm;
  ++frame->size;
  frame->offsets = std::max(frame->offsets, std::abs(c));
  return true;
}

/// @p x minus its components along the frame's normals.
Eigen::Vector3d orthogonalPart(const Frame& frame, const Eigen::Vector3d& x) {
  Eigen::Vector3d w = x;
  for (int pass = 0; pass < 2; ++pass) {
    for (int l = 0; l < frame.size; ++l) {
      w -= frame.q[l].dot(w) * frame.q[l];
    }
  }
  return w;
}

/// A unit vector of R^m (entries beyond m zero) orthogonal to the frame's normals; the frame
/// has fewer than m of them.
Eigen::Vector3d nullDirection(const Frame& frame, int dimension) {
  Eigen::Vector3d best = Eigen::Vector3d::Zero();
  double best_norm = -1.0;
  for (int i = 0; i < dimension; ++i) {
    const Eigen::Vector3d w = orthogonalPart(frame, Eigen::Vector3d::Unit(i));
    const double norm = w.norm();  // at least 1/sqrt(3) for one of the m axes
    if (norm > best_norm) {
      best = w;
      best_norm = norm;
    }
  }
  return best / best_norm;
}

/// One projection: the problem's data and the best feasible candidate found so far.
struct Search {
  const Eigen::Vector3d* normals = nullptr;
  const double* offsets = nullptr;
  int dimension = 0;
  Eigen::Vector3d nominal = Eigen::Vector3d::Zero();
  double radius = 0.0;     ///< a_max; infinity: no ball
  double scale = 0.0;      ///< the largest of ||u_nom|| and a_max (when finite)
  std::uint32_t mask = 0;  ///< half-spaces a candidate must satisfy
  bool found = false;
  Eigen::Vector3d best = Eigen::Vector3d::Zero();
  double best_distance = 0.0;  ///< ||best - u_nom||^2
  double best_offsets = 0.0;   ///< the largest |c| of the planes that gave best
};

/// kFeasibilityTolerance s at @p x, given by planes whose largest |c| is @p offsets.
double tolerance(const Search& search, const Eigen::Vector3d& x, double offsets) {
  return CommandProjection::kFeasibilityTolerance *
         std::max({search.scale, euclideanNorm(x), offsets});
}

bool ballHas(const Search& search, const Eigen::Vector3d& x, double tol) {
  return !std::isfinite(search.radius) || euclideanNorm(x) <= search.radius + tol;
}

/// Whether x is within @p tol, or kFeasibilityTolerance |c_j| if larger, of half-space j.
bool halfSpaceHas(const Search& search, int j, const Eigen::Vector3d& x, double tol) {
  const double own = CommandProjection::kFeasibilityTolerance * std::abs(search.offsets[j]);
  return search.normals[j].dot(x) >= search.offsets[j] - std::max(tol, own);
}

/// Keeps @p x (given by planes whose largest |c| is @p offsets) if it is feasible and nearer
/// u_nom than the best so far.
void consider(Search* search, const Eigen::Vector3d& x, double offsets) {
  const double distance = (x - search->nominal).squaredNorm();
  if (search->found && !(distance < search->best_distance)) {
    return;
  }
  const double tol = tolerance(*search, x, offsets);
  if (!x.allFinite() || !ballHas(*search, x, tol)) {
    return;
  }
  for (int j = 0; j < CommandProjection::kMaxConstraints; ++j) {
    if ((search->mask & bit(j)) != 0U && !halfSpaceHas(*search, j, x, tol)) {
      return;
    }
  }
  search->found = true;
  search->best = x;
  search->best_distance = distance;
  search->best_offsets = offsets;
}

/// The candidates of the active set made of the frame's planes: the projection of u_nom onto
/// their affine set, and, with fewer than m planes, the points nearest u_nom of that set's
/// intersection with the sphere ||u|| = a_max (two points when the affine set is a line, else a
/// circle or sphere, whose nearest point is along u_nom's component in the affine set). None is
/// considered when the projection is no nearer u_nom than the best so far, since no point of the
/// affine set is, nor of those of its supersets.
/// @return ||projection - u_nom||^2, a lower bound on the distances of the supersets' candidates
double addCandidates(Search* search, const Frame& frame) {
  Eigen::Vector3d p0 = Eigen::Vector3d::Zero();  // the affine set's point nearest the origin
  for (int l = 0; l < frame.size; ++l) {
    p0 += frame.z[l] * frame.q[l];
  }
  const Eigen::Vector3d along = orthogonalPart(frame, search->nominal);
  const double bound = (p0 + along - search->nominal).squaredNorm();
  if (search->found && !(bound < search->best_distance)) {
    return bound;
  }
  consider(search, p0 + along, frame.offsets);
  if (!std::isfinite(search->radius) || frame.size >= search->dimension) {
    return bound;
  }
  const double distance = euclideanNorm(p0);
  if (!(distance <= search->radius + tolerance(*search, p0, frame.offsets))) {
    return bound;  // the affine set misses the ball
  }
  const double radius = std::sqrt(
      std::max(0.0, (search->radius - distance) * (search->radius + distance)));  // in the set
  if (search->dimension - frame.size == 1) {
    const Eigen::Vector3d direction = nullDirection(frame, search->dimension);
    consider(search, p0 + radius * direction, frame.offsets);
    consider(search, p0 - radius * direction, frame.offsets);
    return bound;
  }
  const double along_norm = euclideanNorm(along);
  const Eigen::Vector3d direction = along_norm > 0.0 && std::isfinite(along_norm)
                                        ? Eigen::Vector3d(along / along_norm)
                                        : nullDirection(frame, search->dimension);
  consider(search, p0 + radius * direction, frame.offsets);
  return bound;
}

/// Whether a set with that lower bound on its distances can still beat the best candidate.
bool open(const Search& search, double bound) {
  return !search.found || bound < search.best_distance;
}

/// The projection onto the ball, half-spaces @p kept and half-space @p j, given that the
/// projection onto the ball and @p kept violates j: enumerates the active sets that contain j,
/// by size (j alone, the pairs {j, i}, the triples {j, i, l}), skipping the supersets of a set
/// whose affine set is no nearer u_nom than the best feasible candidate found.
/// @return false when no candidate is feasible (the set is empty), else true with search->best
bool projectOntoPlaneOf(Search* search, std::uint32_t kept, int j) {
  search->mask = kept | bit(j);
  search->found = false;
  Frame one;
  addPlane(&one, search->normals[j], search->offsets[j]);  // a unit normal: always independent
  addCandidates(search, one);
  if (search->dimension == 1) {
    return search->found;
  }
  double pair_bounds[CommandProjection::kMaxConstraints];  // +infinity: no independent pair
  for (int i = 0; i < j; ++i) {
    Frame two = one;
    pair_bounds[i] = std::numeric_limits<double>::infinity();
    if ((kept & bit(i)) != 0U && addPlane(&two, search->normals[i], search->offsets[i])) {
      pair_bounds[i] = addCandidates(search, two);
    }
  }
  for (int i = 0; search->dimension == 3 && i < j; ++i) {
    Frame two = one;
    if (pair_bounds[i] == std::numeric_limits<double>::infinity() ||
        !open(*search, pair_bounds[i]) || !addPlane(&two, search->normals[i], search->offsets[i])) {
      continue;
    }
    for (int l = i + 1; l < j; ++l) {
      Frame three = two;
      if (pair_bounds[l] != std::numeric_limits<double>::infinity() &&
          open(*search, pair_bounds[l]) &&
          addPlane(&three, search->normals[l], search->offsets[l])) {
        addCandidates(search, three);
      }
    }
  }
  return search->found;
}

}  // namespace

CommandProjection::CommandProjection(int dimension) : dimension_(dimension) {
  if (dimension < 1 || dimension > 3) {
    throw std::invalid_argument("CommandProjection: the dimension must be 1, 2 or 3, not " +
                                std::to_string(dimension));
  }
  normals_.fill(Eigen::Vector3d::Zero());
  offsets_.fill(0.0);
}

bool CommandProjection::add(const Eigen::Vector3d& normal, double bound) {
  Eigen::Vector3d n = Eigen::Vector3d::Zero();
  n.head(dimension_) = normal.head(dimension_);
  const double norm = euclideanNorm(n);
  if (count_ >= kMaxConstraints || !n.allFinite() || !std::isfinite(bound) || !(norm > 0.0) ||
      !std::isfinite(norm)) {
    return false;
  }
  normals_[count_] = n / norm;
  offsets_[count_] = bound / norm;
  if (!normals_[count_].allFinite() || !std::isfinite(offsets_[count_])) {
    return false;  // b / ||g|| overflows (||g|| subnormal)
  }
  ++count_;
  return true;
}

CommandProjectionResult CommandProjection::project(const Eigen::Vector3d& nominal,
                                                   double max_norm) const {
  if (!nominal.head(dimension_).allFinite()) {
    throw std::invalid_argument("CommandProjection::project: the nominal command is not finite");
  }
  if (!(max_norm > 0.0)) {
    throw std::invalid_argument("CommandProjection::project: max_norm must be positive");
  }
  Search search;
  search.normals = normals_.data();
  search.offsets = offsets_.data();
  search.dimension = dimension_;
  search.nominal.head(dimension_) = nominal.head(dimension_);
  search.radius = max_norm;
  search.scale = euclideanNorm(search.nominal);
  if (std::isfinite(max_norm)) {
    search.scale = std::max(search.scale, max_norm);
  }

  // The projection onto the ball, then onto the ball and the half-spaces kept so far.
  Eigen::Vector3d x = search.nominal;
  double x_offsets = 0.0;  // the largest |c| of the planes that gave x
  if (std::isfinite(max_norm)) {
    clampNorm(x, max_norm);
  }
  CommandProjectionResult result;
  std::uint32_t kept = 0;
  for (int j = 0; j < count_; ++j) {
    if (halfSpaceHas(search, j, x, tolerance(search, x, x_offsets))) {
      kept |= bit(j);  // x stays the projection
    } else if (projectOntoPlaneOf(&search, kept, j)) {
      x = search.best;
      x_offsets = search.best_offsets;
      kept |= bit(j);
    } else {
      result.dropped_mask |= bit(j);
      ++result.dropped;
    }
  }
  if (std::isfinite(max_norm)) {
    clampNorm(x, max_norm);  // the ball holds as computed, not only within the tolerance
  }

  result.command = x;
  for (int i = 0; i < dimension_; ++i) {
    result.changed = result.changed || x(i) != nominal(i);
  }
  const double tol = tolerance(search, x, x_offsets);
  for (int j = 0; j < count_; ++j) {
    const double slack = std::max(tol, kFeasibilityTolerance * std::abs(offsets_[j]));
    if ((kept & bit(j)) != 0U && std::abs(normals_[j].dot(x) - offsets_[j]) <= slack) {
      ++result.active;
      result.active_mask |= bit(j);
    }
  }
  result.ball_active = std::isfinite(max_norm) && euclideanNorm(x) >= max_norm - tol;
  return result;
}

}  // namespace projection_collision_avoidance
