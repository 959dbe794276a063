#include "projection_collision_avoidance/sim/StringStability.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <vector>

namespace projection_collision_avoidance {

StringStabilityFigures stringStabilityFigures(const FormationSummary& summary) {
  const std::vector<SimulationSummary>& followers = summary.followers;
  const std::size_t n = followers.size();
  const auto target = [&summary](std::size_t i) {  // of follower i + 1, 1-based (0: leader)
    return summary.targets.empty() ? static_cast<int>(i) : summary.targets[i];
  };
  constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
  StringStabilityFigures figures;
  bool negligible = false;
  for (std::size_t i = 0; i < n; ++i) {
    const SimulationSummary& f = followers[i];
    const int index = static_cast<int>(i) + 1;
    if (figures.first_outside_bound == 0 && f.max_xi > f.xi_max) {
      figures.first_outside_bound = index;
    }
    if (figures.first_inside_perimeter == 0 && f.min_separation < f.perimeter) {
      figures.first_inside_perimeter = index;
    }
    negligible = negligible || !(f.max_xi >= StringStabilityFigures::kNegligiblePeak);
  }
  double ratio_max = -1.0;
  double log_sum = 0.0;
  int behind = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const int t = target(i);
    if (t < 1) {
      continue;
    }
    const auto j = static_cast<std::size_t>(t - 1);
    const double ratio = followers[i].max_xi / followers[j].max_xi;
    ratio_max = std::max(ratio_max, ratio);
    if (target(j) >= 1) {
      log_sum += std::log(ratio);
      ++behind;
    }
  }
  figures.peak_ratio_max = ratio_max >= 0.0 && !negligible ? ratio_max : kNaN;
  figures.peak_growth = behind > 0 && !negligible ? std::exp(log_sum / behind) : kNaN;
  return figures;
}

}  // namespace projection_collision_avoidance
