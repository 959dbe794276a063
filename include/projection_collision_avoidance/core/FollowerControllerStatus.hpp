#pragma once

#include "projection_collision_avoidance/core/TypeDefs.hpp"

namespace projection_collision_avoidance {

/// Everything the follower computed at one control tick.
template <typename Dims>
struct FollowerControllerStatus {
  /// u_2 = baseline + tracker + feed-forward, saturated, then rate limited
  typename Dims::InputVector command;
  typename Dims::InputVector baseline_command;     ///< G y (2)
  typename Dims::InputVector tracker_command;      ///< u_a (19)
  typename Dims::InputVector feedforward_command;  ///< u_ff (S2) if shared in the command, else 0
  typename Dims::InputVector headway_command;      ///< K_h x_2 (S1); 0 without the time headway
  typename Dims::InputVector fallback_command;     ///< K_f xi_hat in the fallback, else 0
  typename Dims::InputVector slot_command;  ///< u_r (T3) of a turning slot; 0 for a world slot
  typename Dims::StateVector estimate;      ///< xi_hat used at this tick (m)
  double estimate_norm = 0.0;               ///< ||xi_hat|| (m), euclideanNorm()
  double constraint_value = 0.0;            ///< f(xi_hat) (13)
  bool command_saturated = false;           ///< the sum exceeded acceleration_limit and was scaled
  /// The saturated command was more than jerk_limit T from the previous one and was moved to
  /// that distance from it.
  bool command_rate_limited = false;
  bool fallback = false;             ///< this tick ran the fallback (no usable measurement)
  bool projection_active = false;    ///< the projection acted during the period that follows
  double boundary_correction = 0.0;  ///< see EstimatorPeriodReport (m)
  /// step() got a measurement with a non-finite entry: it was treated as missing, and this tick
  /// ran the fallback (a step without a measurement) instead.
  bool measurement_rejected = false;
  /// The leader's input u_1 had a non-finite entry: this tick took it as unknown.
  bool leader_input_rejected = false;
  /// The turning slot's acceleration u_r had a non-finite entry: this tick took it as 0.
  bool slot_acceleration_rejected = false;
  /// The laws' command was not finite (an overflow with huge finite measurements, inputs or
  /// gains) and was replaced: in step() by the fallback's for this tick (fallback is set), in the
  /// fallback by the feed-forward u_ff alone (zero when u_1 is not shared), saturated.
  bool command_overflow = false;
  /// The estimator discarded a non-finite substep and held the estimate (EstimatorPeriodReport).
  bool estimate_held = false;
  /// The neighbours' half-spaces (N3) moved the command (StepInputs::command_constraints).
  bool command_projected = false;
  /// Half-spaces the command was given this tick, held with equality by it, and dropped because
  /// they could not all be met (the less urgent ones; (N3)).
  int constraints_given = 0;
  int constraints_active = 0;
  int constraints_dropped = 0;
  /// With the barrier filter (StepInputs::safety_filter, (B3)): the barrier holding with
  /// equality at the command (its index, the most urgent first; -1: none), and whether the
  /// barriers and the acceleration limit could not all be met this tick.
  int binding_barrier = -1;
  bool barrier_infeasible = false;

  FollowerControllerStatus() = default;
  /// The same status in other (compatible) dimensions, e.g. fixed to bounded: the one place that
  /// lists the fields.
  template <typename OtherDims>
  explicit FollowerControllerStatus(const FollowerControllerStatus<OtherDims>& other) {
    *this = other;
  }
  template <typename OtherDims>
  FollowerControllerStatus& operator=(const FollowerControllerStatus<OtherDims>& other) {
    command = other.command;
    baseline_command = other.baseline_command;
    tracker_command = other.tracker_command;
    feedforward_command = other.feedforward_command;
    headway_command = other.headway_command;
    fallback_command = other.fallback_command;
    slot_command = other.slot_command;
    estimate = other.estimate;
    estimate_norm = other.estimate_norm;
    constraint_value = other.constraint_value;
    command_saturated = other.command_saturated;
    command_rate_limited = other.command_rate_limited;
    fallback = other.fallback;
    projection_active = other.projection_active;
    boundary_correction = other.boundary_correction;
    measurement_rejected = other.measurement_rejected;
    leader_input_rejected = other.leader_input_rejected;
    slot_acceleration_rejected = other.slot_acceleration_rejected;
    command_overflow = other.command_overflow;
    estimate_held = other.estimate_held;
    command_projected = other.command_projected;
    constraints_given = other.constraints_given;
    constraints_active = other.constraints_active;
    constraints_dropped = other.constraints_dropped;
    binding_barrier = other.binding_barrier;
    barrier_infeasible = other.barrier_infeasible;
    return *this;
  }
};

/// The status of a controller whose sizes are known at run time: FollowerControllerStatus with
/// bounded vectors (inline storage: copying one allocates nothing).
using DynamicFollowerStatus = FollowerControllerStatus<GenericDimensions>;

}  // namespace projection_collision_avoidance
