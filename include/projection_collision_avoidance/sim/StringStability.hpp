#pragma once

/// @file
/// The figures of string stability of a formation's run (doc/formations.md, "String
/// stability"): where the followers first leave their bound or enter their perimeter, and how
/// the peak relative error changes from a follower's target to the follower.

#include "projection_collision_avoidance/sim/SampledSimulator.hpp"

namespace projection_collision_avoidance {

/// Figures of a FormationSummary, with peak_i = max_t ||xi_i(t)|| of follower i (1-based) and
/// t(i) its target (FormationSummary::targets; a line chain, t(i) = i - 1, when that is empty).
/// Ratios are taken along the links between followers, peak_i / peak_t(i) for t(i) >= 1: in a
/// line chain peak_i / peak_{i-1}, in a V chain along each arm; a star has none.
struct StringStabilityFigures {
  /// The first follower i with peak_i > xi_max,i; 0 when none. In a chain a follower does not
  /// depend on those behind it, so a chain of N followers keeps every bound for N < this.
  int first_outside_bound = 0;
  /// The first follower whose min separation to its target is below its perimeter alpha ||d_i||;
  /// 0 when none.
  int first_inside_perimeter = 0;
  /// max over followers i with t(i) >= 1 of peak_i / peak_t(i): <= 1 means that no follower's
  /// peak exceeds its target's. NaN without such a follower or with a peak below
  /// kNegligiblePeak.
  double peak_ratio_max = 0.0;
  /// The geometric mean of peak_i / peak_t(i) over the followers whose target looks at a
  /// follower itself (t(t(i)) >= 1), i.e. behind the followers that see the leader's
  /// disturbance: (peak_N / peak_2)^(1 / (N - 2)) in a line chain. NaN when there is none or a
  /// peak is below kNegligiblePeak.
  double peak_growth = 0.0;

  /// Peaks below this (m) are rounding noise: their ratios mean nothing.
  static constexpr double kNegligiblePeak = 1e-9;
};

/// The figures of @p summary (followers in index order).
StringStabilityFigures stringStabilityFigures(const FormationSummary& summary);

}  // namespace projection_collision_avoidance
