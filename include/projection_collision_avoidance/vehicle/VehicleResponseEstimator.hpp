#pragma once

/// @file
/// How a velocity-commanded vehicle follows its commands, read off its measured velocity: how
/// often its state changes, which earlier command its velocity shows (the response delay) and
/// what fraction of the commanded velocity change it realises (doc/vehicles.md).

#include <array>
#include <limits>

#include "projection_collision_avoidance/vehicle/CommandHistory.hpp"

namespace projection_collision_avoidance {

/// Options of VehicleResponseEstimator.
struct ResponseEstimatorOptions {
  double period = 0.01;         ///< T (s), > 0: candidate delays are 0, T, 2T, …
  double max_delay = 0.3;       ///< s, ≥ 0: the longest delay considered; ≤ 255 T
  double averaging_time = 1.0;  ///< s, > 0: the memory of the averages
  /// s, > 0: the realised fraction compares velocity changes over segments at least this long
  /// (a change every T would be measured against the noise of one sample)
  double segment = 0.2;
  /// m/s², ≥ 0: a segment counts for the realised fraction when its commands asked for at least
  /// this acceleration (‖Δc‖ ≥ min_acceleration Δt)
  double min_acceleration = 0.05;
};

/// What the estimator has seen so far.
struct VehicleResponse {
  double update_interval = std::numeric_limits<double>::quiet_NaN();  ///< s between changes
  double delay = 0.0;  ///< s: the velocity measured at t is the command in force at t − delay
  /// realised / commanded velocity change (1: all of it); NaN while the commands hardly vary
  double realised_fraction = std::numeric_limits<double>::quiet_NaN();
  std::size_t observations = 0;  ///< changes of state seen
};

/// Each time the vehicle's state changes (a new velocity v measured, taken at t_m), for every
/// candidate delay L = jT ≤ max_delay, e_L ← (1 − w) e_L + w ‖v − c(t_m − L)‖² with c(t) the
/// command in force at t and w = 1 − e^(−Δt/averaging_time) (Δt since the previous change).
/// The delay is the L of least e_L; it changes only when another candidate's e is below 0.8 of
/// the current one's, so that noise among near-equal candidates (constant commands) does not
/// move it. The realised fraction is ρ = ⟨Δv · Δc⟩ / ⟨‖Δc‖²⟩ over the same averages, with
/// Δv and Δc over segments of at least `segment` s between changes: Δv = v(t_m) − v(t_s),
/// Δc = Σ of the increments sent in [t_s − D, t_m − D), averaged over the segments whose commands
/// asked for an acceleration (‖Δc‖ ≥ min_acceleration (t_m − t_s)); it is NaN until 5 such
/// segments were seen. The history must keep (segment + max_delay) / T commands. Assumed: a vehicle
/// that realises its command after a pure delay (its velocity loop faster than its state updates)
/// and unit gain (a weaker vehicle biases the delay: 0.08 s for 0.1 s at a gain of 0.6); a
/// first-order lag τ shows as a delay of about τ. Allocates nothing after construction.
class VehicleResponseEstimator {
 public:
  /// @throws ParameterError naming vehicle.velocity.period, .max_delay or .averaging_time
  explicit VehicleResponseEstimator(const ResponseEstimatorOptions& options);

  /// Notes the state change to @p velocity (m/s, the history's axes) taken at @p changed_at (s),
  /// against the commands of @p history. A change not later than the previous one starts the
  /// estimate afresh (time went back); a velocity not finite or of the wrong size is ignored.
  void observe(const AxisVector& velocity, double changed_at, const CommandHistory& history);

  /// Forgets everything (delay back to 0).
  void reset();

  const VehicleResponse& response() const { return response_; }
  const ResponseEstimatorOptions& options() const { return options_; }
  /// Number of candidate delays (max_delay / T + 1).
  int candidates() const { return candidates_; }

 private:
  static constexpr int kMaxCandidates = 256;

  /// Closes the segment of the realised fraction at a change at least `segment` after its start.
  void noteSegment(const AxisVector& velocity, double changed_at, const CommandHistory& history);

  ResponseEstimatorOptions options_;
  int candidates_;
  std::array<double, kMaxCandidates> error_{};
  int chosen_ = 0;
  AxisVector previous_;
  double previous_time_ = 0.0;
  double cross_ = 0.0;           ///< ⟨Δv · Δc⟩
  double commanded_ = 0.0;       ///< ⟨‖Δc‖²⟩
  int excited_ = 0;              ///< segments that asked for an acceleration
  AxisVector segment_velocity_;  ///< v at the segment's start (empty: none yet)
  double segment_time_ = 0.0;    ///< t_s (s)
  VehicleResponse response_;
};

}  // namespace projection_collision_avoidance
