#pragma once

/// Drives for the convoy path's tests (test_target_path*.cpp): a point on a circle and a straight
/// drive recorded in steps.

#include <algorithm>
#include <cmath>

#include <Eigen/Core>

#include "projection_collision_avoidance/core/TargetPath.hpp"

namespace projection_collision_avoidance {

inline Eigen::Vector3d onCircle(double radius, double angle) {
  return {radius * std::cos(angle), radius * std::sin(angle), 0.0};
}

/// Drives @p path in straight steps of at most @p step from @p from to @p to (both recorded).
inline void driveTo(TargetPath* path, const Eigen::Vector3d& from, const Eigen::Vector3d& to,
                    double step) {
  const int steps = std::max(1, static_cast<int>(std::ceil((to - from).norm() / step - 1e-9)));
  for (int k = 1; k <= steps; ++k) {
    path->record(from + (to - from) * (static_cast<double>(k) / steps));
  }
}

}  // namespace projection_collision_avoidance
