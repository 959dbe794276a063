#include "projection_collision_avoidance/core/ExactDiscretization.hpp"

#include <unsupported/Eigen/MatrixFunctions>

namespace projection_collision_avoidance {

ExactDiscretization ExactDiscretization::compute(const Eigen::MatrixXd& A, double dt) {
  const Eigen::Index n = A.rows();
  Eigen::MatrixXd augmented = Eigen::MatrixXd::Zero(2 * n, 2 * n);
  augmented.topLeftCorner(n, n) = A * dt;
  augmented.topRightCorner(n, n) = Eigen::MatrixXd::Identity(n, n) * dt;
  const Eigen::MatrixXd exponential = augmented.exp();
  return ExactDiscretization{exponential.topLeftCorner(n, n), exponential.topRightCorner(n, n)};
}

}  // namespace projection_collision_avoidance
