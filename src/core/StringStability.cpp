#include "projection_collision_avoidance/StringStability.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <vector>

namespace projection_collision_avoidance {

StringStabilityFigures stringStabilityFigures(const FormationSummary& summary) {
  const std::vector<SimulationSummary>& followers = summary.followers;
  const std::size_t n = followers.size();
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
  figures.peak_ratio_max = n >= 2 && !negligible ? 0.0 : kNaN;
  if (!std::isnan(figures.peak_ratio_max)) {
    for (std::size_t i = 0; i + 1 < n; ++i) {
      figures.peak_ratio_max =
          std::max(figures.peak_ratio_max, followers[i + 1].max_xi / followers[i].max_xi);
    }
  }
  figures.peak_growth = kNaN;
  if (n >= 3 && !negligible) {
    figures.peak_growth =
        std::pow(followers[n - 1].max_xi / followers[1].max_xi, 1.0 / static_cast<double>(n - 2));
  }
  return figures;
}

}  // namespace projection_collision_avoidance
