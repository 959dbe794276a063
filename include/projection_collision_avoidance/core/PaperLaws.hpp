#pragma once

/// @file
/// The paper's laws, one function each, named by their equation numbers (doc/math.md gives them
/// in full). Every user calls these: the sampled controller (FollowerController, with
/// CollisionFreeTracker and CollisionFreeEstimator), the continuous-time loop
/// (ContinuousDynamics), the simulators and ControllerDesign. The bounds (4), (14a) and the
/// constraint (13) are in BallConstraint.hpp, the projection (15) in ProjectionOperator.hpp, the
/// platoon laws (S1), (S2) in PlatoonLaws.hpp. For fixed-size and bounded vectors (Dims) none of
/// these allocates memory.

#include "projection_collision_avoidance/core/BallConstraint.hpp"
#include "projection_collision_avoidance/core/TypeDefs.hpp"

namespace projection_collision_avoidance {

/// Baseline law (2): G y (m/s^2 for a double integrator), with y = C xi (m, m/s).
template <typename Dims>
typename Dims::InputVector baselineCommand(const typename Dims::FeedbackGainMatrix& baseline_gain,
                                           const typename Dims::OutputVector& y) {
  return baseline_gain * y;
}

/// CF tracker (19): u_a = G_e (y - y_hat) + S_21 y_hat (m/s^2), y_hat = C xi_hat the
/// estimated output (m, m/s).
template <typename Dims>
typename Dims::InputVector trackerCommand(const typename Dims::FeedbackGainMatrix& tracker_gain,
                                          const typename Dims::FeedbackGainMatrix& reference_gain,
                                          const typename Dims::OutputVector& y,
                                          const typename Dims::OutputVector& estimated_output) {
  return tracker_gain * (y - estimated_output) + reference_gain * estimated_output;
}

/// sat() of (10): scales a finite @p command longer than @p limit (m/s^2; infinite: no bound)
/// onto it, same direction (clampNorm()); true when it did. A non-finite command stays so.
template <typename Input>
bool saturateCommand(Input* command, double limit) {
  return clampNorm(*command, limit) > 0.0;
}

/// Augmented command (10): u_2 = sat(G y + u_a + u_ff [+ u_h]) (m/s^2), with u_ff the shared
/// leader acceleration (0 if not shared) and u_h the time-headway term (S1) when given (may be
/// null); true when sat() acted. The sum is formed before sat() in that order.
template <typename Dims>
bool augmentedCommand(const typename Dims::InputVector& baseline,
                      const typename Dims::InputVector& tracker,
                      const typename Dims::InputVector& feedforward,
                      const typename Dims::InputVector* headway, double limit,
                      typename Dims::InputVector* command) {
  *command = baseline + tracker + feedforward;
  if (headway != nullptr) {
    *command += *headway;
  }
  return saturateCommand(command, limit);
}

/// The augmentation that acts under (10): u_2 - G y - u_ff (m/s^2), what sat() (and a rate
/// limit) left of u_a [+ u_h]; the estimator (11) integrates it in place of u_a.
template <typename Input>
Input actingAugmentation(const Input& command, const Input& baseline, const Input& feedforward) {
  return command - baseline - feedforward;
}

/// w of the estimator drift (11) when the leader's input is shared into the estimator:
/// w = B (u_1 - u_ff) (m/s), with u_1 the shared acceleration a_1 and u_ff what the command took.
template <typename Dims>
typename Dims::StateVector leaderInputDrift(const typename Dims::InputMatrix& input_matrix,
                                            const typename Dims::InputVector& leader_input,
                                            const typename Dims::InputVector& feedforward) {
  return input_matrix * (leader_input - feedforward);
}

/// The part of the estimator drift (11) held over a control period: c = w - B u_a - L y (m/s),
/// u_a the augmentation that acts, w as leaderInputDrift() or 0; see estimatorDrift().
template <typename Dims>
typename Dims::StateVector estimatorHeldInput(
    const typename Dims::InputMatrix& input_matrix,
    const typename Dims::ObserverGainMatrix& observer_gain, const typename Dims::OutputVector& y,
    const typename Dims::InputVector& augmentation, const typename Dims::StateVector& w) {
  return w - input_matrix * augmentation - observer_gain * y;
}

/// Estimator drift (11), unprojected: h = A_c xi_hat - B u_a + L (C xi_hat - y) + w
/// = (A_c + L C) xi_hat + c (m/s), with F = A_c + L C and c = estimatorHeldInput(). (With F = A
/// and c = w - B (u_2 - u_ff) it is the fallback's prediction, (11) without a measurement.)
template <typename Dims>
typename Dims::StateVector estimatorDrift(const typename Dims::StateMatrix& estimator_matrix,
                                          const typename Dims::StateVector& estimate,
                                          const typename Dims::StateVector& held_input) {
  return estimator_matrix * estimate + held_input;
}

/// The leader's acceleration as shared: a_1 = u_1 + pinv(B) u_d (m/s^2); for a double
/// integrator pinv(B) u_d is the velocity-rate part of u_d (m/s^2). Any Eigen vector types.
template <typename Input, typename Pseudoinverse, typename State>
Input leaderAcceleration(const Input& leader_input, const Pseudoinverse& input_pseudoinverse,
                         const State& disturbance) {
  Input acceleration = leader_input;
  acceleration += input_pseudoinverse * disturbance;
  return acceleration;
}

/// The one choice of the leader's acceleration a follower is told (m/s^2): a_1 = u_1 + pinv(B)
/// u_d (leaderAcceleration()) when the disturbance is shared (@p disturbance_shared, the key
/// controller.leader_information.disturbance) and known (@p disturbance not empty), else u_1.
template <typename Input, typename Pseudoinverse, typename State>
Input sharedLeaderAcceleration(bool disturbance_shared, const Input& leader_input,
                               const Pseudoinverse& input_pseudoinverse, const State& disturbance) {
  if (disturbance_shared && disturbance.size() > 0) {
    return leaderAcceleration(leader_input, input_pseudoinverse, disturbance);
  }
  return leader_input;
}

}  // namespace projection_collision_avoidance
