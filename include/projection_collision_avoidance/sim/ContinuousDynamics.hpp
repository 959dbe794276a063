#pragma once

#include <cmath>
#include <stdexcept>

#include "projection_collision_avoidance/core/AugmentedLaw.hpp"
#include "projection_collision_avoidance/core/BallConstraint.hpp"
#include "projection_collision_avoidance/core/CollisionFreeEstimator.hpp"
#include "projection_collision_avoidance/core/ControllerDesign.hpp"
#include "projection_collision_avoidance/core/PaperLaws.hpp"
#include "projection_collision_avoidance/core/ParameterError.hpp"
#include "projection_collision_avoidance/core/TypeDefs.hpp"

namespace projection_collision_avoidance {

/// The state of the paper's pair in continuous time: z = [x_1; x_2; xi_hat].
template <typename Dims>
struct ContinuousLoopState {
  typename Dims::StateVector leader;    ///< x_1 (m, m/s for a double integrator)
  typename Dims::StateVector follower;  ///< x_2
  typename Dims::StateVector estimate;  ///< xi_hat (m, m/s)
};

/// The signals of the continuous loop at one instant.
template <typename Dims>
struct ContinuousLoopSignals {
  typename Dims::StateVector relative_error;  ///< xi = x_1 - x_2 - d
  typename Dims::InputVector baseline;        ///< G y (2)
  typename Dims::InputVector tracker;         ///< u_a (19)
  typename Dims::InputVector command;         ///< u_2 = sat(G y + u_a + u_ff) (10)
  double constraint_value = 0.0;              ///< f(xi_hat) (13)
  bool projection_active = false;             ///< Proj changed the estimator's drift (15)
};

/// The closed loop of the paper's pair with the laws acting at every instant (no sampling),
/// the model of its Sec. IV:
///   x_1' = A x_1 + B u_1 + u_d,   x_2' = A x_2 + B u_2,   u_2 = sat(G y + u_a + u_ff) (10),
///   u_a = G_e (y - C xi_hat) + S_21 C xi_hat (19),
///   xi_hat' = Proj(h),  h = A_c xi_hat - B u_acts + L (C xi_hat - y) [+ B (a_1 - u_ff)] (11)-(15),
/// with y = C (x_1 - x_2 - d), a_1 = u_1 [+ pinv(B) u_d] and u_ff = a_1 as configured by
/// controller.leader_information (else 0), and Proj the Gamma^-1-weighted operator of the notes.
/// sat() is the controller's: none unless controller.acceleration_limit is set. u_acts is the
/// augmentation that acts: u_a, or u_2 - G y - u_ff while sat() acts (actingAugmentation()). The
/// same composition as FollowerController (AugmentedLaw, and the drift and projection of
/// CollisionFreeEstimator), except that u_2 and y are not held over a period. The controller's rate
/// limit (controller.jerk_limit), a bound per control period, has no counterpart here and is
/// refused, and so are the time headway (S1) and the shaped feed-forward (S2), which only the
/// sampled loop models.
template <typename Dims>
class ContinuousDynamics {
 public:
  using StateVector = typename Dims::StateVector;
  using InputVector = typename Dims::InputVector;
  using OutputVector = typename Dims::OutputVector;
  using State = ContinuousLoopState<Dims>;
  using Signals = ContinuousLoopSignals<Dims>;

  /// @param design validated parameters whose sizes fit Dims (std::invalid_argument otherwise),
  ///        without a jerk_limit, time_headway or shaped feed-forward (ParameterError naming the
  ///        key otherwise)
  explicit ContinuousDynamics(const ControllerDesign& design)
      : law_(design),
        estimator_(design),
        share_disturbance_(design.parameters.leader_disturbance_shared),
        in_command_(design.parameters.leader_input_in_command) {
    const AgentModel& model = design.parameters.model;
    if (!Dims::fits(model.stateDimension(), model.inputDimension(), model.outputDimension())) {
      throw std::invalid_argument("ContinuousDynamics: model sizes do not fit the dimensions");
    }
    if (std::isfinite(design.parameters.jerk_limit)) {
      throw ParameterError("controller.jerk_limit",
                           "the continuous-time loop has no control period to limit the "
                           "command's change over; remove the key or run the sampled loop");
    }
    const ControllerParameters& p = design.parameters;
    if (p.time_headway != 0.0 || p.feedforward_gain != 1.0 || p.feedforward_time_constant != 0.0) {
      throw ParameterError(p.time_headway != 0.0 ? "controller.spacing.time_headway"
                           : p.feedforward_gain != 1.0
                               ? "controller.leader_information.feedforward.gain"
                               : "controller.leader_information.feedforward.time_constant",
                           "is modelled by the sampled loop only (cf_sim without --continuous)");
    }
    state_matrix_ = model.A;
    input_matrix_ = model.B;
    output_matrix_ = model.C;
    separation_ = design.parameters.separation;
    input_pseudoinverse_ = design.input_pseudoinverse;
  }

  /// z' at one instant, and the loop's signals there. Allocates no memory.
  /// @param z the state
  /// @param leader_input u_1 (m/s^2 for a double integrator)
  /// @param disturbance u_d (position-rate part m/s, velocity-rate part m/s^2)
  /// @param[out] derivative z'
  /// @param[out] signals the signals at z (may be null)
  void evaluate(const State& z, const InputVector& leader_input, const StateVector& disturbance,
                State* derivative, Signals* signals = nullptr) const {
    const StateVector xi = z.leader - z.follower - separation_;
    const OutputVector y = output_matrix_ * xi;
    const InputVector acceleration = sharedLeaderAcceleration(  // a_1
        share_disturbance_, leader_input, input_pseudoinverse_, disturbance);
    InputVector feedforward = InputVector::Zero(input_matrix_.cols());
    if (in_command_) {
      feedforward = acceleration;
    }
    AugmentedTerms<Dims> terms;  // (2), (19), (10)
    law_.compose(y, output_matrix_ * z.estimate, feedforward, nullptr, &terms);
    // (11) with the augmentation that acts, as the sampled controller's estimator integrates it
    const InputVector acting = law_.acting(terms, terms.command, feedforward, false);
    const StateVector held =
        estimator_.heldInput(y, acting, law_.knownDrift(&acceleration, feedforward));
    bool active = false;
    derivative->estimate = estimator_.derivative(z.estimate, held, &active);  // (15)
    derivative->leader = state_matrix_ * z.leader + input_matrix_ * leader_input + disturbance;
    derivative->follower = state_matrix_ * z.follower + input_matrix_ * terms.command;
    if (signals != nullptr) {
      signals->relative_error = xi;
      signals->baseline = terms.baseline;
      signals->tracker = terms.tracker;
      signals->command = terms.command;
      signals->constraint_value = estimator_.constraint().value(z.estimate);
      signals->projection_active = active;
    }
  }

  /// The constraint f of (13) on xi_hat.
  const BallConstraint& constraint() const { return estimator_.constraint(); }

 private:
  AugmentedLaw<Dims> law_;                  // (2), (19), (10)
  CollisionFreeEstimator<Dims> estimator_;  // the drift (11) and its projection (15); no state
  bool share_disturbance_;
  bool in_command_;
  typename Dims::StateMatrix state_matrix_;             // A
  typename Dims::InputMatrix input_matrix_;             // B
  typename Dims::OutputMatrix output_matrix_;           // C
  StateVector separation_;                              // d
  typename Dims::StateGainMatrix input_pseudoinverse_;  // pinv(B)
};

}  // namespace projection_collision_avoidance
