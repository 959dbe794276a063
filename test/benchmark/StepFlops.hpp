#pragma once

/// @file
/// Floating-point operations of one FollowerController::step() on the tracking path (leader
/// information off, command not saturated), counted from the code: a dense r x c matrix times a
/// vector is r (2c - 1) flops, a squared norm of k entries 2k - 1, a norm 2k (with the square
/// root); +, -, *, / and sqrt count one each, comparisons and copies none.

namespace projection_collision_avoidance {
namespace benchmarking {

constexpr long matrixVector(long rows, long cols) { return rows * (2 * cols - 1); }
constexpr long squaredNorm(long k) { return 2 * k - 1; }
constexpr long norm(long k) { return 2 * k; }

/// Flops of one step for n states, m inputs, p outputs and s RK4 substeps; @p projected: the
/// projection acts at every derivative evaluation (the estimate on the bound, pushed outward).
constexpr long stepFlops(long n, long m, long p, long s, bool projected) {
  const long constraint = squaredNorm(n) + 5;  // f = ((1 + eps) |x|^2 - xi_max^2) scale   (13)
  const long laws = matrixVector(p, n)         // y_hat = C xi_hat
                    + matrixVector(m, p)       // G y                                  (2)
                    + p + 2 * matrixVector(m, p) + m  // u_a = G_e (y - y_hat) + S_21 y_hat (19)
                    + 2 * m                           // u_2 = G y + u_a + u_ff               (10)
                    + norm(n) + constraint            // status: |xi_hat|, f(xi_hat)
                    + norm(m);                        // saturation test |u_2|
  const long held = matrixVector(n, m) + matrixVector(n, p) + 2 * n + 1;  // c = w - B u_a - L y; h
  long derivative = matrixVector(n, n) + n          // (A_c + L C) xi_hat + c                 (11)
                    + constraint + squaredNorm(n);  // f, grad_f^T h (as xi_hat . h)        (7)
  if (projected) {
    derivative += matrixVector(n, n) + squaredNorm(n) + 2 + n + n;  // - f (.)/(.) Gamma^-1 grad_f
  }
  const long substep = 4 * derivative   // k1 .. k4
                       + 3 * 2 * n + 2  // stages xi_hat + (h/2) k1, + (h/2) k2, + h k3
                       + 7 * n + 1      // xi_hat + h/6 (k1 + 2 k2 + 2 k3 + k4)
                       + 2 + norm(n);   // move into the bound: radius, |xi_hat|
  return laws + held + s * substep;
}

}  // namespace benchmarking
}  // namespace projection_collision_avoidance
