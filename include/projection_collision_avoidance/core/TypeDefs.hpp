#pragma once

/// @file
/// Domain types of the core: Eigen vectors and matrices whose sizes are fixed at compile time
/// where the model fixes them (double integrators in 1, 2 and 3 axes) and bounded otherwise, so
/// that no control step allocates memory.

#include <Eigen/Core>

namespace projection_collision_avoidance {

/// Largest state, input and output dimensions of a model whose sizes are known only at run time.
constexpr int kMaxStateDimension = 12;
constexpr int kMaxInputDimension = 6;
constexpr int kMaxOutputDimension = 12;

/// A matrix of compile-time size Rows x Cols, or of run-time size bounded by MaxRows x MaxCols
/// (storage inline, never on the heap). Row vectors are stored row-major as Eigen requires.
template <int Rows, int Cols, int MaxRows, int MaxCols>
using BoundedMatrix =
    Eigen::Matrix<double, Rows, Cols,
                  ((MaxRows == 1 && MaxCols != 1) ? Eigen::RowMajor : Eigen::ColMajor) |
                      Eigen::AutoAlign,
                  MaxRows, MaxCols>;

/// Compile-time description of an agent model: N states, M inputs, P outputs, each either a
/// number or Eigen::Dynamic (then bounded by kMax*Dimension).
template <int N, int M, int P>
struct Dimensions {
  static constexpr int kStates = N;
  static constexpr int kInputs = M;
  static constexpr int kOutputs = P;
  static constexpr int kMaxStates = N == Eigen::Dynamic ? kMaxStateDimension : N;
  static constexpr int kMaxInputs = M == Eigen::Dynamic ? kMaxInputDimension : M;
  static constexpr int kMaxOutputs = P == Eigen::Dynamic ? kMaxOutputDimension : P;

  using StateVector = BoundedMatrix<N, 1, kMaxStates, 1>;
  using InputVector = BoundedMatrix<M, 1, kMaxInputs, 1>;
  using OutputVector = BoundedMatrix<P, 1, kMaxOutputs, 1>;
  using StateMatrix = BoundedMatrix<N, N, kMaxStates, kMaxStates>;          ///< n x n: A, Gamma
  using InputMatrix = BoundedMatrix<N, M, kMaxStates, kMaxInputs>;          ///< n x m: B
  using OutputMatrix = BoundedMatrix<P, N, kMaxOutputs, kMaxStates>;        ///< p x n: C
  using FeedbackGainMatrix = BoundedMatrix<M, P, kMaxInputs, kMaxOutputs>;  ///< m x p: G, G_e
  using ObserverGainMatrix = BoundedMatrix<N, P, kMaxStates, kMaxOutputs>;  ///< n x p: L, pinv(C)
  using StateGainMatrix = BoundedMatrix<M, N, kMaxInputs, kMaxStates>;      ///< m x n: K_f

  /// Whether a model of n states, m inputs and p outputs fits: each size equal to the fixed one,
  /// or within the bound where the size is dynamic.
  static constexpr bool fits(Eigen::Index n, Eigen::Index m, Eigen::Index p) {
    return (N == Eigen::Dynamic || N == n) && (M == Eigen::Dynamic || M == m) &&
           (P == Eigen::Dynamic || P == p) && n <= kMaxStates && m <= kMaxInputs &&
           p <= kMaxOutputs;
  }
};

/// Double integrator on one axis: x = [p; v], u = acceleration, y = x.
using DoubleIntegrator1D = Dimensions<2, 1, 2>;
/// Double integrator in the plane: x = [p_x, p_y, v_x, v_y].
using DoubleIntegrator2D = Dimensions<4, 2, 4>;
/// Double integrator in space: x = [p_x, p_y, p_z, v_x, v_y, v_z].
using DoubleIntegrator3D = Dimensions<6, 3, 6>;
/// Any (A, B, C) up to the kMax*Dimension bounds.
using GenericDimensions = Dimensions<Eigen::Dynamic, Eigen::Dynamic, Eigen::Dynamic>;

}  // namespace projection_collision_avoidance
