#include "projection_collision_avoidance/core/TargetPath.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace projection_collision_avoidance {

TargetPath::TargetPath(int capacity, double spacing, double retrace_width)
    : capacity_(capacity), spacing_(spacing), retrace_width_(retrace_width) {
  if (capacity < 2 || !(spacing > 0.0) || !std::isfinite(spacing) || !(retrace_width >= 0.0) ||
      !std::isfinite(retrace_width)) {
    throw std::invalid_argument("TargetPath: capacity >= 2, spacing > 0, retrace_width >= 0");
  }
  points_.resize(static_cast<std::size_t>(capacity));
  arcs_.resize(static_cast<std::size_t>(capacity));
  reset(Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitX());
}

void TargetPath::reset(const Eigen::Vector3d& start, const Eigen::Vector3d& direction) {
  const double norm = direction.norm();
  direction_ = norm > 0.0 && std::isfinite(norm) ? Eigen::Vector3d(direction / norm)
                                                 : Eigen::Vector3d::UnitX();
  first_ = 0;
  count_ = 0;
  tip_ = start.allFinite() ? start : Eigen::Vector3d::Zero();
  push(tip_, 0.0);
  progress_ = 0.0;
  retracing_ = false;
  start_kept_ = true;
}

const Eigen::Vector3d& TargetPath::point(int i) const {
  return points_[static_cast<std::size_t>((first_ + i) % capacity_)];
}

double TargetPath::arc(int i) const {
  return arcs_[static_cast<std::size_t>((first_ + i) % capacity_)];
}

void TargetPath::push(const Eigen::Vector3d& position, double sigma) {
  if (count_ == capacity_) {  // the oldest point goes
    first_ = (first_ + 1) % capacity_;
    --count_;
    start_kept_ = false;
  }
  const auto slot = static_cast<std::size_t>((first_ + count_) % capacity_);
  points_[slot] = position;
  arcs_[slot] = sigma;
  ++count_;
}

Eigen::Vector3d TargetPath::oldestDirection() const {
  if (!start_kept_ && count_ >= 2) {
    const Eigen::Vector3d segment = point(1) - point(0);
    const double length = segment.norm();
    if (length > 0.0) {
      return segment / length;
    }
  }
  return direction_;
}

void TargetPath::latestLine(Eigen::Vector3d* end, Eigen::Vector3d* along) const {
  *end = point(count_ - 1);
  if (count_ >= 2) {
    const Eigen::Vector3d segment = *end - point(count_ - 2);
    const double length = segment.norm();
    if (length > 0.0) {
      *along = segment / length;
      return;
    }
  }
  *along = direction_;
}

void TargetPath::record(const Eigen::Vector3d& target) {
  if (!target.allFinite()) {
    return;
  }
  tip_ = target;
  // Driving back over the path: off with the points driven back over; behind the only point,
  // on the virtual road, the point itself slides back to the target's foot.
  Eigen::Vector3d end;
  Eigen::Vector3d along;
  double ahead = 0.0;
  double across = 0.0;
  for (;;) {
    latestLine(&end, &along);
    ahead = (target - end).dot(along);
    across = ((target - end) - ahead * along).norm();
    if (!(ahead < 0.0 && across <= retrace_width_)) {
      break;
    }
    retracing_ = true;
    if (count_ >= 2) {
      --count_;
      continue;
    }
    points_[static_cast<std::size_t>(first_)] += ahead * along;
    arcs_[static_cast<std::size_t>(first_)] += ahead;
    ahead = 0.0;
    break;
  }
  // While retracing, a target beside the latest segment's line (within retrace_width, less than
  // spacing ahead) adds no point: a reversing target that drifts sideways stays on its path.
  if (retracing_ && ahead < spacing_ && across <= retrace_width_) {
    progress_ = arc(count_ - 1) + (target - point(count_ - 1)).norm();
    return;
  }
  retracing_ = false;
  const double beyond = (target - point(count_ - 1)).norm();
  if (beyond >= spacing_) {
    push(target, arc(count_ - 1) + beyond);
    progress_ = arc(count_ - 1);
  } else {
    progress_ = arc(count_ - 1) + beyond;
  }
}

Eigen::Vector3d TargetPath::at(double sigma) const {
  const double oldest = arc(0);
  if (sigma <= oldest) {
    return point(0) - (oldest - sigma) * oldestDirection();
  }
  const double latest = arc(count_ - 1);
  if (sigma >= latest) {  // on the way from the latest point to the target
    const Eigen::Vector3d to_tip = tip_ - point(count_ - 1);
    const double length = to_tip.norm();
    const Eigen::Vector3d along =
        length > 0.0 ? Eigen::Vector3d(to_tip / length) : Eigen::Vector3d(direction_);
    return point(count_ - 1) + (sigma - latest) * along;
  }
  // The segment [i, i + 1] holding sigma: the arcs increase along the ring.
  int low = 0;
  int high = count_ - 1;
  while (high - low > 1) {
    const int middle = (low + high) / 2;
    (arc(middle) <= sigma ? low : high) = middle;
  }
  const double span = arc(high) - arc(low);
  const double t = span > 0.0 ? (sigma - arc(low)) / span : 0.0;
  return point(low) + t * (point(high) - point(low));
}

double TargetPath::lastFarPoint(const Eigen::Vector3d& a, const Eigen::Vector3d& u, double upper,
                                const Eigen::Vector3d& target, double chord) {
  // ||a + t u − target||^2 = chord^2, u a unit vector: t^2 + 2 t b + c = 0.
  const Eigen::Vector3d offset = a - target;
  const double b = offset.dot(u);
  const double c = offset.squaredNorm() - chord * chord;
  const double discriminant = b * b - c;
  if (discriminant < 0.0) {
    return -1.0;  // the whole line is farther than chord: cannot be (the end at upper is closer)
  }
  const double lower_root = -b - std::sqrt(discriminant);
  return lower_root >= 0.0 && lower_root <= upper ? lower_root : -1.0;
}

double TargetPath::walkBack(double sigma, const Eigen::Vector3d& target, double chord) const {
  if ((target - at(sigma)).norm() >= chord) {
    return sigma;
  }
  // Closer than chord at sigma: the far points before it lie at the lower root of a segment whose
  // start is far enough, walking back one segment at a time.
  double upper = sigma;
  for (int i = count_ - 1; i >= 0; --i) {
    const double start = arc(i);
    if (start >= upper) {
      continue;
    }
    const Eigen::Vector3d a = point(i);
    const Eigen::Vector3d b = at(upper);
    const double length = (b - a).norm();
    if (length > 0.0) {
      const double t = lastFarPoint(a, (b - a) / length, length, target, chord);
      if (t >= 0.0) {
        return start + t;
      }
    }
    if ((target - a).norm() >= chord) {
      return start;
    }
    upper = start;
  }
  // The virtual road behind the oldest point: P = P_0 − tau e, tau >= 0; the far points are those
  // beyond the larger root of ||P_0 − tau e − target|| = chord.
  const Eigen::Vector3d e = oldestDirection();
  const Eigen::Vector3d offset = point(0) - target;
  const double b = -offset.dot(e);
  const double c = offset.squaredNorm() - chord * chord;
  const double tau = -b + std::sqrt(std::max(0.0, b * b - c));
  return arc(0) - std::max(0.0, tau);
}

}  // namespace projection_collision_avoidance
