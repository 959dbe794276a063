#pragma once

/// @file
/// The path a convoy follower keeps to (doc/math.md, "Convoys on the target's path"): the
/// target's positions, recorded at a fixed spacing into a ring of fixed capacity (C1), read at an
/// arc length, and the goal point that keeps a chord from the target (C2).

#include <vector>

#include <Eigen/Core>

namespace projection_collision_avoidance {

/// The target's path P(sigma), sigma its arc length (m), (C1):
///  - record() appends the target's position once it lies @p spacing or more from the latest
///    point; when the ring is full the oldest point goes;
///  - a target that drives back over its own path (behind the latest point along the latest
///    segment, within @p retrace_width of that segment's line) takes the points it drove back
///    over off the path, so that its progress s goes down as it reverses; while it does, a
///    position beside the latest segment (within @p retrace_width, less than @p spacing ahead)
///    adds no point, so a reversing target that drifts sideways stays on its path;
///  - the path goes on from the latest point straight to the target, s = sigma_last + ||p_t −
///    P_last||, and before the oldest point it goes on straight backward: a virtual road behind
///    it, along the initial direction while the start is kept, then along the oldest segment.
/// P is continuous in sigma. Every function allocates nothing after construction.
class TargetPath {
 public:
  /// @param capacity points kept, >= 2
  /// @param spacing m between recorded points, > 0
  /// @param retrace_width m, >= 0
  TargetPath(int capacity, double spacing, double retrace_width);

  /// Starts the path at @p start (m), the target's position, heading along the unit
  /// @p direction (the direction from the follower's slot to its target): one point at sigma = 0.
  void reset(const Eigen::Vector3d& start, const Eigen::Vector3d& direction);

  /// Notes the target at @p target (m), (C1). A non-finite position is ignored.
  void record(const Eigen::Vector3d& target);

  /// s (m): the arc length of the target's latest position along the path.
  double progress() const { return progress_; }
  /// P(@p sigma) (m), for any finite sigma (C1).
  Eigen::Vector3d at(double sigma) const;
  /// The largest sigma' <= @p sigma with ||@p target − P(sigma')|| >= @p chord (m), (C2). It
  /// always exists: the virtual road behind the oldest point is unbounded.
  double walkBack(double sigma, const Eigen::Vector3d& target, double chord) const;

  /// Points on the path (1 .. capacity).
  int size() const { return count_; }
  /// sigma of the oldest point (m).
  double oldestArc() const { return arc(0); }

 private:
  const Eigen::Vector3d& point(int i) const;  // i = 0 (oldest) .. count_ - 1
  double arc(int i) const;
  void push(const Eigen::Vector3d& position, double sigma);
  /// The latest point @p end and the unit direction of the latest segment @p along (the initial
  /// direction while there is one point).
  void latestLine(Eigen::Vector3d* end, Eigen::Vector3d* along) const;
  /// The unit direction of the path at its oldest point (forward).
  Eigen::Vector3d oldestDirection() const;
  /// The largest t in [0, length] of a + t u with ||a + t u − target|| >= chord at or below
  /// @p upper, when the segment's end at @p upper is closer than chord; negative when none.
  static double lastFarPoint(const Eigen::Vector3d& a, const Eigen::Vector3d& u, double upper,
                             const Eigen::Vector3d& target, double chord);

  int capacity_;
  double spacing_;
  double retrace_width_;
  std::vector<Eigen::Vector3d> points_;
  std::vector<double> arcs_;
  int first_ = 0;  ///< ring index of the oldest point
  int count_ = 0;
  Eigen::Vector3d direction_ = Eigen::Vector3d::UnitX();  ///< initial forward direction
  Eigen::Vector3d tip_ = Eigen::Vector3d::Zero();         ///< the target's latest position
  double progress_ = 0.0;
  bool retracing_ = false;  ///< points were taken off since the latest one was added
  bool start_kept_ = true;  ///< the start is the oldest point: the road keeps direction_
};

}  // namespace projection_collision_avoidance
