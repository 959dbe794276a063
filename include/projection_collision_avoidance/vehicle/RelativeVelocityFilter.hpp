#pragma once

/// @file
/// The relative velocity reconstructed from relative positions alone (a camera, UWB, a UVDAR-like
/// sensor, or tf lookups between the agents' frames), so that the follower gets the full
/// relative state y = [p; v̂] its baseline law needs (doc/vehicles.md, "Position only").

#include <Eigen/Core>

#include "projection_collision_avoidance/vehicle/VelocityCommandIntegrator.hpp"

namespace projection_collision_avoidance {

/// Options of RelativeVelocityFilter.
struct VelocityFilterOptions {
  int axes = 2;  ///< 1, 2 or 3
  /// ω (rad/s), > 0: both poles of the estimation error at −ω (in discrete time at e^(−ωΔt)).
  /// Larger ω: less lag (2a/ω m/s under a constant relative acceleration a), more noise.
  double bandwidth = 20.0;
  /// Δt (s) beyond which the filter starts again from the next two positions, > 0.
  double max_gap = 0.5;
  /// Δt (s), > 0, below which a position is not used: closer than this to the last position
  /// used, its difference from it is mostly the sensor's noise (1 cm over 5 ms is 2 m/s) or a
  /// glitch's (a repeated sample, a burst). 0.005 s passes every sensor up to 200 Hz.
  double min_interval = 0.005;
  /// Largest relative speed (m/s, > 0) a vehicle pair can have: an estimate beyond it is refused
  /// and the filter starts again from that position.
  double max_speed = 50.0;
};

/// What became of one relative position.
enum class VelocityFilterVerdict {
  kEstimated,      ///< velocity estimated: state valid
  kStarted,        ///< the first position (or the first after a gap): no velocity yet
  kNotIncreasing,  ///< stamp not after the previous one: ignored
  kTooSoon,        ///< less than min_interval after the last position used: ignored
  kTooFast,        ///< an estimate beyond max_speed: not given, the filter started from it
  kRefused,        ///< a non-finite position or stamp, or a wrong size: ignored
};

/// "estimated", "started", "stamp not increasing", "too soon", "too fast", "refused".
const char* toString(VelocityFilterVerdict verdict);

/// A critically damped α-β filter on a constant-velocity model of the relative position p
/// (each axis alike). At a position p(t_k), Δt = t_k − t_(k−1), θ = e^(−ω Δt):
///   predict  p̂ ← p̂ + v̂ Δt;  r = p − p̂
///   correct  p̂ ← p̂ + (1 − θ²) r;  v̂ ← v̂ + (1 − θ)² r / Δt
/// whose error dynamics have the double pole θ: the discrete counterpart of the observer
/// ė = [[−2ω, 1], [−ω², 0]] e. The second position starts v̂ as a difference quotient. Under a
/// constant relative acceleration a the velocity lags by a Δt ((1 + θ)/(1 − θ) − ½) ≈ 2a/ω.
/// A position less than min_interval after the last one used is ignored (kTooSoon), and an
/// estimate faster than max_speed is never given (kTooFast): so no velocity above max_speed
/// ever leaves the filter. Never throws on inputs.
class RelativeVelocityFilter {
 public:
  /// @throws std::invalid_argument naming the option (axes, bandwidth, max_gap, min_interval,
  ///         max_speed) out of range
  explicit RelativeVelocityFilter(const VelocityFilterOptions& options);

  /// Takes the relative position @p position (m, the first axes() entries) measured at @p t (s);
  /// on kEstimated, @p state = [p; v̂] (2·axes entries: the position as measured, the velocity
  /// estimated, m and m/s, ‖v̂‖ ≤ max_speed).
  VelocityFilterVerdict update(double t, const Eigen::Vector3d& position, Eigen::VectorXd* state);

  /// Forgets everything: the next position starts again.
  void reset() { samples_ = 0; }

  const VelocityFilterOptions& options() const { return options_; }

 private:
  VelocityFilterOptions options_;
  int samples_ = 0;  ///< 0, 1, or 2 (estimating)
  double time_ = 0.0;
  Eigen::Vector3d position_ = Eigen::Vector3d::Zero();  ///< p̂
  Eigen::Vector3d velocity_ = Eigen::Vector3d::Zero();  ///< v̂
};

}  // namespace projection_collision_avoidance
