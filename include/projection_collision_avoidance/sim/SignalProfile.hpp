#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

namespace projection_collision_avoidance {

/// A constant vector applied for start <= t < end.
struct Pulse {
  double start = 0.0;  ///< s
  double end = 0.0;    ///< s
  Eigen::VectorXd vector;
};

/// amplitude * sin(2 pi frequency t + phase).
struct Sinusoid {
  Eigen::VectorXd amplitude;
  double frequency = 0.0;  ///< Hz
  double phase = 0.0;      ///< rad
};

/// A time signal made of pulses and sinusoids (their sum); zero when empty. Used for the
/// leader's input u_1(t) and its disturbance u_d(t).
struct SignalProfile {
  std::vector<Pulse> pulses;
  std::vector<Sinusoid> sinusoids;

  /// The signal at time t (s), a vector of @p size entries.
  Eigen::VectorXd value(double t, Eigen::Index size) const;

  /// Adds the signal at time t (s) to @p result (its size entries); allocates no memory.
  void addTo(double t, Eigen::Ref<Eigen::VectorXd> result) const;
  /// Adds the pulses' part of the signal at time t (s) to @p result; allocates no memory.
  void addPulsesTo(double t, Eigen::Ref<Eigen::VectorXd> result) const;
  /// Adds the sinusoids' part of the signal at time t (s) to @p result; allocates no memory.
  void addSinusoidsTo(double t, Eigen::Ref<Eigen::VectorXd> result) const;
  /// Whether the signal has sinusoids (is not piecewise constant).
  bool hasSinusoids() const { return !sinusoids.empty(); }
  /// Whether a pulse edge lies strictly inside (t0, t1); allocates no memory.
  bool hasEdgeWithin(double t0, double t1) const;
  /// Pulse edges strictly inside (t0, t1), sorted.
  std::vector<double> edgesWithin(double t0, double t1) const;

  /// Checks every vector has @p size finite entries, start < end and finite times, finite
  /// frequencies and phases; throws ParameterError naming key.pulses.i.* / key.sinusoids.i.*.
  void validate(const std::string& key, Eigen::Index size) const;
};

}  // namespace projection_collision_avoidance
