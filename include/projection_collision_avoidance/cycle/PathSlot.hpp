#pragma once

#include <cstdint>

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

  /// One step at the time @p time_ns (ns) its inputs describe: the measurement's stamp when
  /// @p known, else the step's. The reference advances by the time since the step before (T when
  /// it is one period), not by a period per call, so that it keeps to the measured own state
  /// whichever step reads which measurement: a step on the same measurement as the one before
  /// gives the same sample, one after a skipped measurement advances two periods.
  /// With @p known the target is @p own_position + relative position and
  /// @p own_velocity + relative velocity (@p relative = x_target − x_i, m and m/s; @p own_position
  /// at @p time_ns); without it the target is unknown to the reference (its goal holds, r comes
  /// to rest) and D keeps the last target. The first call must be known (it resets the path at
  /// the target). Writes D into @p slot (n entries) and u_r into @p acceleration (axes entries).
  void step(std::int64_t time_ns, bool known, const GenericDimensions::InputVector& own_position,
            const GenericDimensions::InputVector& own_velocity,
            const GenericDimensions::StateVector& relative, GenericDimensions::StateVector* slot,
            GenericDimensions::InputVector* acceleration);

  /// The latest sample of the reference (r, r', r'', the goal, the path's progress).
  const ConvoySample& sample() const { return sample_; }

  /// Time went back (a new timeline): the next step's time starts the reference's clock afresh.
  void restartClock() { have_time_ = false; }

 private:
  ConvoyReference reference_;
  Eigen::Vector3d direction_ = Eigen::Vector3d::UnitX();  ///< d_p / ||d_p||: the road
  int axes_;
  bool started_ = false;
  GenericDimensions::StateVector target_;  ///< x_target of the latest known step
  ConvoySample sample_;
  double period_;             ///< T (s)
  std::int64_t period_ns_;    ///< T (ns), rounded
  std::int64_t time_ns_ = 0;  ///< the time of the latest sample
  bool have_time_ = false;
};

}  // namespace projection_collision_avoidance
