#pragma once

/// @file
/// The checks of parameter values behind every validator (the core's and the simulation's):
/// each throws ParameterError naming the key.

#include <cmath>
#include <string>

#include <Eigen/Core>

#include "projection_collision_avoidance/core/LinearAlgebra.hpp"
#include "projection_collision_avoidance/core/ParameterError.hpp"

namespace projection_collision_avoidance::detail {

inline std::string shapeOf(Eigen::Index rows, Eigen::Index cols) {
  return std::to_string(rows) + "x" + std::to_string(cols);
}

/// Throws ParameterError(key) unless M is rows x cols with finite entries.
inline void requireMatrix(const std::string& key, const Eigen::MatrixXd& M, Eigen::Index rows,
                          Eigen::Index cols) {
  if (M.rows() != rows || M.cols() != cols) {
    throw ParameterError(key,
                         "must be " + shapeOf(rows, cols) + ", got " + shapeOf(M.rows(), M.cols()));
  }
  if (!allFinite(M)) {
    throw ParameterError(key, "has a non-finite entry");
  }
}

/// Throws ParameterError(key) unless v has size entries, all finite.
inline void requireVector(const std::string& key, const Eigen::VectorXd& v, Eigen::Index size) {
  if (v.size() != size) {
    throw ParameterError(
        key, "must have " + std::to_string(size) + " entries, got " + std::to_string(v.size()));
  }
  if (!v.allFinite()) {
    throw ParameterError(key, "has a non-finite entry");
  }
}

inline void requireFinite(const std::string& key, double value) {
  if (!std::isfinite(value)) {
    throw ParameterError(key, "must be finite");
  }
}

}  // namespace projection_collision_avoidance::detail
