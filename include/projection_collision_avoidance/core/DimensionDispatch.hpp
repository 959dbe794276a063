#pragma once

#include <utility>

#include "projection_collision_avoidance/core/AgentModel.hpp"
#include "projection_collision_avoidance/core/TypeDefs.hpp"

namespace projection_collision_avoidance {

/// Calls visitor(Dims{}) with the compile-time dimensions that fit the model: the fixed-size
/// double-integrator types when (n, m, p) is (2, 1, 2), (4, 2, 4) or (6, 3, 6), and the bounded
/// dynamic GenericDimensions otherwise. Every call of the visitor must return the same type.
template <typename Visitor>
decltype(auto) visitDimensions(const AgentModel& model, Visitor&& visitor) {
  const int n = model.stateDimension();
  const int m = model.inputDimension();
  const int p = model.outputDimension();
  if (n == 2 && m == 1 && p == 2) {
    return std::forward<Visitor>(visitor)(DoubleIntegrator1D{});
  }
  if (n == 4 && m == 2 && p == 4) {
    return std::forward<Visitor>(visitor)(DoubleIntegrator2D{});
  }
  if (n == 6 && m == 3 && p == 6) {
    return std::forward<Visitor>(visitor)(DoubleIntegrator3D{});
  }
  return std::forward<Visitor>(visitor)(GenericDimensions{});
}

}  // namespace projection_collision_avoidance
