#pragma once

#include <functional>
#include <string>
#include <vector>

#include "projection_collision_avoidance/sim/Scenario.hpp"

namespace projection_collision_avoidance {

/// What of the leader's acceleration a_1 = u_1 + pinv(B) u_d the follower is given.
enum class LeaderSharing {
  kNone,       ///< nothing: the paper's setting
  kCommand,    ///< a_1 fed forward in the command: u_2 = G y + u_a + a_1
  kEstimator,  ///< a_1 in the estimator's model of xi': h += B a_1
  kBoth,       ///< both
};

/// "none", "command", "estimator", "both".
std::string toString(LeaderSharing sharing);

/// One controller configuration of the sweep.
struct SweepConfiguration {
  bool tracker = true;
  LeaderSharing sharing = LeaderSharing::kNone;
};

/// The grid and the search of sweepDisturbance().
struct SweepOptions {
  int directions = 16;      ///< phi_j = 2 pi j / directions, j = 0 .. directions - 1
  double max_size = 20.0;   ///< largest ||u_d|| tried
  double size_step = 0.25;  ///< the scan's step in ||u_d||
  double tolerance = 1e-3;  ///< width of the bisection's final bracket

  /// Throws ParameterError naming sweep.directions / .max_size / .size_step / .tolerance.
  void validate() const;
};

/// The largest safe disturbances of one configuration in one direction.
struct SweepPoint {
  SweepConfiguration configuration;
  double direction = 0.0;  ///< phi (rad)
  /// Largest s such that every run with size s' <= s keeps max ||xi|| <= xi_max: the scan's
  /// last safe size before its first failure, refined by bisection; max_size if none failed.
  double bound_limit = 0.0;
  bool bound_capped = false;  ///< no size up to max_size failed the bound
  /// The same for the separation: min ||p_1 - p_2|| >= alpha ||d|| (the perimeter).
  double perimeter_limit = 0.0;
  bool perimeter_capped = false;
};

/// Called after each point (progress reports).
using SweepProgress = std::function<void(const SweepPoint&)>;

/// The controller configurations of the sweep: tracker off and on, each with every sharing mode.
std::vector<SweepConfiguration> sweepConfigurations();

/// The scenario of one sweep run: @p base (a pair of double integrators with one disturbance
/// pulse, whose window [start, end) is kept) with the pulse's vector replaced by
///   u_d = s (cos(phi) [r; 0] + sin(phi) [0; r]),   r = d / ||d||,
/// so phi = 0 pushes the leader's position away from the follower, phi = pi/2 accelerates it
/// away, and phi in (pi, 3 pi / 2) pushes it back toward the follower in both parts (the paper's
/// u_d = [-2, -2] is s = 2 sqrt(2), phi = 5 pi / 4). The tracker is set as configured; with
/// sharing the leader input and its disturbance's acceleration part go where configured.
/// @throws ParameterError for a base scenario that is not such a pair
Scenario sweepScenario(const Scenario& base, const SweepConfiguration& configuration,
                       double direction, double size);

/// For every configuration of sweepConfigurations() and every direction of the grid, the largest
/// disturbance that keeps ||xi|| <= xi_max and the largest that keeps the separation outside the
/// perimeter (each from the ticks of simulate()). Throws ParameterError for a bad base scenario
/// or options.
std::vector<SweepPoint> sweepDisturbance(const Scenario& base, const SweepOptions& options,
                                         const SweepProgress& progress = {});

}  // namespace projection_collision_avoidance
