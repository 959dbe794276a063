#pragma once

#include <string>

#include <Eigen/Core>

namespace projection_collision_avoidance {

/// The LTI model shared by the leader and the follower (paper, eq. (1)):
/// x' = A x + B u, y = C x, with the leading position_dimension entries of x being positions.
struct AgentModel {
  Eigen::MatrixXd A;               ///< n x n state matrix
  Eigen::MatrixXd B;               ///< n x m input matrix
  Eigen::MatrixXd C;               ///< p x n output matrix (relative measurement y = C xi)
  int position_dimension = 0;      ///< number of leading state entries that are positions (m)
  int double_integrator_axes = 0;  ///< k > 0 when the model is a k-axis double integrator

  int stateDimension() const { return static_cast<int>(A.rows()); }
  int inputDimension() const { return static_cast<int>(B.cols()); }
  int outputDimension() const { return static_cast<int>(C.rows()); }
  bool isDoubleIntegrator() const { return double_integrator_axes > 0; }
};

/// The k-axis double integrator p'' = u: x = [p; v] in R^2k, A = [[0, I], [0, 0]], B = [0; I],
/// C = I. Throws ParameterError("model.dimension") unless 1 <= axes <= 3.
AgentModel makeDoubleIntegrator(int axes);

/// Checks sizes and finiteness of a model; throws ParameterError naming "model.A", "model.B",
/// "model.C" or "model.position_dimension".
void validateAgentModel(const AgentModel& model);

}  // namespace projection_collision_avoidance
