#pragma once

#include <Eigen/Core>

#include "projection_collision_avoidance/core/ConvoyReference.hpp"
#include "projection_collision_avoidance/core/TypeDefs.hpp"

namespace projection_collision_avoidance {

/// The slot of a convoy follower in the control cycle (formation.slots: path, doc/math.md
/// "Convoys on the target's path"): the target's state is the follower's own (its controlled
/// point's, from odometry) plus the measured relative state; the reference r moves along the
/// target's path (C1)-(C5) and gives D = x_target − [r; r'] and u_r = r'' (C4), so that the
/// controller's xi = [r − p_i; r' − v_i]. Allocates nothing after construction.
class PathSlot {
 public:
  /// @param parameters formation.path, validated
  /// @param period T (s)
  /// @param separation d_i (n = 2 axes entries): its norm sets the gap, its direction the road
  /// @param axes position axes, 1 to 3
  PathSlot(const ConvoyParameters& parameters, double period,
           const GenericDimensions::StateVector& separation, int axes);

  /// Whether the first known target has started the path.
  bool started() const { return started_; }

  /// One control period. With @p known the target is @p own_position + relative position and
  /// @p own_velocity + relative velocity (@p relative = x_target − x_i, m and m/s); without it the
  /// target is unknown to the reference (its goal holds, r comes to rest) and D keeps the last
  /// target. The first call must be known (it resets the path at the target). Writes D into
  /// @p slot (n entries) and u_r into @p acceleration (axes entries).
  void step(bool known, const GenericDimensions::InputVector& own_position,
            const GenericDimensions::InputVector& own_velocity,
            const GenericDimensions::StateVector& relative, GenericDimensions::StateVector* slot,
            GenericDimensions::InputVector* acceleration);

  /// The latest sample of the reference (r, r', r'', the goal, the path's progress).
  const ConvoySample& sample() const { return sample_; }

 private:
  ConvoyReference reference_;
  Eigen::Vector3d direction_ = Eigen::Vector3d::UnitX();  ///< d_p / ||d_p||: the road
  int axes_;
  bool started_ = false;
  GenericDimensions::StateVector target_;  ///< x_target of the latest known step
  ConvoySample sample_;
};

}  // namespace projection_collision_avoidance
