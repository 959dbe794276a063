#pragma once

/// @file
/// The laws a follower adds for string stability in a chain (doc/math.md, "Platoons"): a
/// constant time-headway spacing policy (S1) and a shaped feed-forward of the target's shared
/// acceleration (S2). Both are off by default (h = 0, kappa = 1, tau = 0), and then leave the
/// paper's laws untouched.

#include <Eigen/Core>

#include "projection_collision_avoidance/core/ControllerParameters.hpp"

namespace projection_collision_avoidance {

/// The keys' own checks (no matrix is used): throws ParameterError naming
/// controller.spacing.time_headway (not finite, negative, over 100 s, or on a model that is not
/// a double integrator), controller.leader_information.feedforward.gain (outside [0, 1]) or
/// .time_constant (not finite, negative or over 1000 s), or controller.leader_information
/// .feedforward when gain or time_constant differ from 1 and 0 while nothing is shared into the
/// command.
void validatePlatoonParameters(const ControllerParameters& parameters);

/// The gain K_h (m x n) of the time-headway term of the command, (S1):
///   u_h = K_h x_2,   K_h = -G C M,   M = [[0, h I], [0, 0]],
/// with x_2 = [p_2; v_2] the follower's own state and h = time_headway (s). The follower
/// regulates xi - M x_2 (its slot moved back by h v_2, along its velocity) while the CF
/// estimator keeps the paper's xi = x_1 - x_2 - d and its bound. Zero when h = 0.
/// @param parameters validated (validatePlatoonParameters() and the matrices' sizes)
/// @throws ParameterError("controller.spacing.time_headway") when the follower's own loop
///         A - B G C (I + M) is not Hurwitz
Eigen::MatrixXd timeHeadwayGain(const ControllerParameters& parameters);

/// The smoothing factor a = exp(-T / tau) of (S2); 0 when tau = 0 (no smoothing).
double feedforwardSmoothing(const ControllerParameters& parameters);

/// The feed-forward of the target's shared acceleration a_hat (as received, held over losses),
/// shaped by a gain kappa and a first-order low-pass of time constant tau, (S2):
///   u_ff(k) = a u_ff(k-1) + (1 - a) kappa a_hat(k),   a = exp(-T / tau),   u_ff(-1) = 0.
/// With kappa = 1 and tau = 0, u_ff = a_hat exactly. Allocates no memory.
template <typename InputVector>
class FeedforwardFilter {
 public:
  FeedforwardFilter(double gain, double smoothing, Eigen::Index size)
      : gain_(gain), smoothing_(smoothing), value_(InputVector::Zero(size)) {}

  /// True when the filter changes a_hat (kappa != 1 or tau > 0).
  bool shapes() const { return gain_ != 1.0 || smoothing_ > 0.0; }

  /// One tick of (S2) with the received @p shared acceleration; returns u_ff(k).
  const InputVector& apply(const InputVector& shared) {
    value_ = smoothing_ * value_ + (1.0 - smoothing_) * gain_ * shared;
    return value_;
  }

  /// Back to u_ff(-1) = 0 (when the target's acceleration is unknown at a tick).
  void reset() { value_.setZero(); }

 private:
  double gain_;
  double smoothing_;
  InputVector value_;
};

}  // namespace projection_collision_avoidance
