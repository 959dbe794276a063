#pragma once

/// @file
/// The vehicle layer's small vectors.

#include <Eigen/Core>

#include "projection_collision_avoidance/core/TypeDefs.hpp"

namespace projection_collision_avoidance {

/// A vector of 1 to 3 axes (m/s or m/s²), stored inline.
using AxisVector = BoundedMatrix<Eigen::Dynamic, 1, 3, 1>;

}  // namespace projection_collision_avoidance
