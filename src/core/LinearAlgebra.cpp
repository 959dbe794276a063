#include "projection_collision_avoidance/core/LinearAlgebra.hpp"

#include <cmath>
#include <sstream>
#include <string>

#include <Eigen/Eigenvalues>
#include <Eigen/LU>

namespace projection_collision_avoidance {

Eigen::MatrixXd solveContinuousLyapunov(const Eigen::MatrixXd& F, const Eigen::MatrixXd& Q,
                                        double* residual) {
  const Eigen::Index n = F.rows();
  // vec(Gamma F) = (F^T (x) I) vec(Gamma) and vec(F^T Gamma) = (I (x) F^T) vec(Gamma), with
  // vec() stacking columns.
  Eigen::MatrixXd kronecker = Eigen::MatrixXd::Zero(n * n, n * n);
  const Eigen::MatrixXd identity = Eigen::MatrixXd::Identity(n, n);
  for (Eigen::Index i = 0; i < n; ++i) {
    for (Eigen::Index j = 0; j < n; ++j) {
      kronecker.block(i * n, j * n, n, n) += F(j, i) * identity;
      kronecker.block(i * n, j * n, n, n) += identity(i, j) * F.transpose();
    }
  }
  const Eigen::VectorXd rhs = -Eigen::Map<const Eigen::VectorXd>(Q.data(), n * n);
  const Eigen::VectorXd solution = kronecker.fullPivLu().solve(rhs);
  Eigen::MatrixXd gamma = Eigen::Map<const Eigen::MatrixXd>(solution.data(), n, n);
  gamma = 0.5 * (gamma + gamma.transpose()).eval();
  if (residual != nullptr) {
    const double q_norm = Q.norm();
    *residual = (gamma * F + F.transpose() * gamma + Q).norm() / (q_norm > 0.0 ? q_norm : 1.0);
  }
  return gamma;
}

Eigen::VectorXcd eigenvalues(const Eigen::MatrixXd& M) {
  return Eigen::EigenSolver<Eigen::MatrixXd>(M, false).eigenvalues();
}

bool isHurwitz(const Eigen::MatrixXd& M, double tolerance) {
  if (!allFinite(M)) {
    return false;
  }
  const double limit = -tolerance * (1.0 + M.norm());
  const Eigen::VectorXcd values = eigenvalues(M);
  for (Eigen::Index i = 0; i < values.size(); ++i) {
    if (!(values(i).real() < limit)) {
      return false;
    }
  }
  return true;
}

std::string formatEigenvalues(const Eigen::VectorXcd& values) {
  std::ostringstream out;
  out.precision(6);
  out << "[";
  for (Eigen::Index i = 0; i < values.size(); ++i) {
    if (i > 0) {
      out << ", ";
    }
    out << values(i).real();
    if (values(i).imag() != 0.0) {
      out << (values(i).imag() > 0.0 ? "+" : "-") << std::abs(values(i).imag()) << "i";
    }
  }
  out << "]";
  return out.str();
}

bool allFinite(const Eigen::MatrixXd& M) { return M.allFinite(); }

}  // namespace projection_collision_avoidance
