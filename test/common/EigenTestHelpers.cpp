#include "EigenTestHelpers.hpp"

#include <Eigen/QR>

namespace projection_collision_avoidance {
namespace testing {

Eigen::MatrixXd randomSpd(std::mt19937& rng, int n, double low, double high) {
  std::normal_distribution<double> normal;
  std::uniform_real_distribution<double> uniform(low, high);
  Eigen::MatrixXd M(n, n);
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) {
      M(i, j) = normal(rng);
    }
  }
  const Eigen::MatrixXd Q = Eigen::HouseholderQR<Eigen::MatrixXd>(M).householderQ();
  Eigen::VectorXd values(n);
  for (int i = 0; i < n; ++i) {
    values(i) = uniform(rng);
  }
  return Q * values.asDiagonal() * Q.transpose();
}

Eigen::VectorXd randomVector(std::mt19937& rng, int n, double scale) {
  std::normal_distribution<double> normal(0.0, scale);
  Eigen::VectorXd v(n);
  for (int i = 0; i < n; ++i) {
    v(i) = normal(rng);
  }
  return v;
}

Eigen::VectorXd randomOnSphere(std::mt19937& rng, int n, double radius) {
  Eigen::VectorXd v = randomVector(rng, n);
  return radius * v / v.norm();
}

}  // namespace testing
}  // namespace projection_collision_avoidance
