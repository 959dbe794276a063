#include "projection_collision_avoidance/core/AgentModel.hpp"

#include "projection_collision_avoidance/core/ParameterError.hpp"
#include "projection_collision_avoidance/core/TypeDefs.hpp"
#include "projection_collision_avoidance/core/ValidationChecks.hpp"

namespace projection_collision_avoidance {

AgentModel makeDoubleIntegrator(int axes) {
  if (axes < 1 || axes > 3) {
    throw ParameterError("model.dimension",
                         "must be 1, 2 or 3 spatial axes, got " + std::to_string(axes));
  }
  const int n = 2 * axes;
  AgentModel model;
  model.A = Eigen::MatrixXd::Zero(n, n);
  model.A.topRightCorner(axes, axes).setIdentity();
  model.B = Eigen::MatrixXd::Zero(n, axes);
  model.B.bottomRows(axes).setIdentity();
  model.C = Eigen::MatrixXd::Identity(n, n);
  model.position_dimension = axes;
  model.double_integrator_axes = axes;
  return model;
}

void validateAgentModel(const AgentModel& model) {
  const Eigen::Index n = model.A.rows();
  if (n < 1 || n > kMaxStateDimension) {
    throw ParameterError("model.A", "must have 1 to " + std::to_string(kMaxStateDimension) +
                                        " rows, got " + std::to_string(n));
  }
  detail::requireMatrix("model.A", model.A, n, n);
  const Eigen::Index m = model.B.cols();
  if (m < 1 || m > kMaxInputDimension) {
    throw ParameterError("model.B", "must have 1 to " + std::to_string(kMaxInputDimension) +
                                        " columns, got " + std::to_string(m));
  }
  detail::requireMatrix("model.B", model.B, n, m);
  const Eigen::Index p = model.C.rows();
  if (p < 1 || p > kMaxOutputDimension) {
    throw ParameterError("model.C", "must have 1 to " + std::to_string(kMaxOutputDimension) +
                                        " rows, got " + std::to_string(p));
  }
  detail::requireMatrix("model.C", model.C, p, n);
  if (model.position_dimension < 1 || model.position_dimension > n) {
    throw ParameterError("model.position_dimension", "must be between 1 and the state dimension " +
                                                         std::to_string(n) + ", got " +
                                                         std::to_string(model.position_dimension));
  }
}

}  // namespace projection_collision_avoidance
