#pragma once

/// @file
/// The figures of string stability of a formation's run (doc/formations.md, "String
/// stability"): where the followers first leave their bound or enter their perimeter, and how
/// the peak relative error changes from one follower to the next.

#include "projection_collision_avoidance/ClosedLoopSimulator.hpp"

namespace projection_collision_avoidance {

/// Figures of a FormationSummary, with peak_i = max_t ||xi_i(t)|| of follower i (1-based).
struct StringStabilityFigures {
  /// The first follower i with peak_i > xi_max,i; 0 when none. In a chain a follower does not
  /// depend on those behind it, so a chain of N followers keeps every bound for N < this.
  int first_outside_bound = 0;
  /// The first follower whose min separation to its target is below its perimeter alpha ||d_i||;
  /// 0 when none.
  int first_inside_perimeter = 0;
  /// max over i = 1 .. N - 1 of peak_{i+1} / peak_i: <= 1 means that no follower's peak exceeds
  /// that of the agent ahead. NaN with fewer than 2 followers or a peak below kNegligiblePeak.
  double peak_ratio_max = 0.0;
  /// (peak_N / peak_2)^(1 / (N - 2)): the geometric mean of the ratios behind follower 1, the
  /// only follower that sees the leader's disturbance itself. NaN with fewer than 3 followers or
  /// a peak below kNegligiblePeak.
  double peak_growth = 0.0;

  /// Peaks below this (m) are rounding noise: their ratios mean nothing.
  static constexpr double kNegligiblePeak = 1e-9;
};

/// The figures of @p summary (followers in index order).
StringStabilityFigures stringStabilityFigures(const FormationSummary& summary);

}  // namespace projection_collision_avoidance
