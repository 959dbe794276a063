#pragma once

/// @file
/// Linear-algebra checks used when parameters load (never in a control step).

#include <string>

#include <Eigen/Core>

namespace projection_collision_avoidance {

/// Solves the continuous Lyapunov equation Gamma F + F^T Gamma = -Q for Gamma (n x n) by its
/// Kronecker form (F^T (x) I + I (x) F^T) vec(Gamma) = -vec(Q). The result is symmetrised.
/// @param residual set to ||Gamma F + F^T Gamma + Q||_F / ||Q||_F
Eigen::MatrixXd solveContinuousLyapunov(const Eigen::MatrixXd& F, const Eigen::MatrixXd& Q,
                                        double* residual);

/// Eigenvalues of a square matrix.
Eigen::VectorXcd eigenvalues(const Eigen::MatrixXd& M);

/// True when every eigenvalue of M has a real part below -tolerance * (1 + ||M||).
bool isHurwitz(const Eigen::MatrixXd& M, double tolerance = 1e-9);

/// "[-1+0.5i, -1-0.5i]": eigenvalues for an error message.
std::string formatEigenvalues(const Eigen::VectorXcd& values);

/// True when every entry is finite.
bool allFinite(const Eigen::MatrixXd& M);

}  // namespace projection_collision_avoidance
