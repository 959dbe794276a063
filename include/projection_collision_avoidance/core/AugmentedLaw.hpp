#pragma once

#include <stdexcept>

#include "projection_collision_avoidance/core/CollisionFreeTracker.hpp"
#include "projection_collision_avoidance/core/ControllerDesign.hpp"
#include "projection_collision_avoidance/core/PaperLaws.hpp"
#include "projection_collision_avoidance/core/TypeDefs.hpp"

namespace projection_collision_avoidance {

/// The terms of the augmented command (10) at one instant (m/s^2 for a double integrator).
template <typename Dims>
struct AugmentedTerms {
  typename Dims::InputVector baseline;  ///< G y (2)
  typename Dims::InputVector tracker;   ///< u_a (19)
  typename Dims::InputVector headway;   ///< K_h x_2 (S1); zero when it does not act
  typename Dims::InputVector command;   ///< u_2 = sat(G y + u_a + u_ff [+ K_h x_2]) (10)
  bool headway_acting = false;          ///< the headway term is in the command
  bool saturated = false;               ///< sat() of (10) changed the command
};

/// The one composition of the paper's laws, shared by the sampled controller
/// (FollowerController) and the continuous-time loop (ContinuousDynamics): the command (10) from
/// the baseline law (2), the CF tracker (19), the shared leader acceleration u_ff and the time
/// headway (S1); the augmentation that acts under it, which the CF estimator (11) integrates;
/// and the estimator's known drift w from the leader's acceleration. Allocates no memory.
template <typename Dims>
class AugmentedLaw {
 public:
  using StateVector = typename Dims::StateVector;
  using InputVector = typename Dims::InputVector;
  using OutputVector = typename Dims::OutputVector;
  using Terms = AugmentedTerms<Dims>;

  /// @param design validated parameters whose sizes fit Dims (std::invalid_argument otherwise)
  explicit AugmentedLaw(const ControllerDesign& design)
      : tracker_(design),
        acceleration_limit_(design.parameters.acceleration_limit),
        headway_(design.parameters.time_headway > 0.0),
        in_estimator_(design.parameters.leader_input_in_estimator) {
    const AgentModel& model = design.parameters.model;
    if (!Dims::fits(model.stateDimension(), model.inputDimension(), model.outputDimension())) {
      throw std::invalid_argument("AugmentedLaw: model sizes do not fit the dimensions");
    }
    input_matrix_ = model.B;
    baseline_gain_ = design.parameters.baseline_gain;
    headway_gain_ = design.headway_gain;
  }

  /// The command (10) and its terms: u_2 = sat(G y + u_a + u_ff [+ K_h x_2]) with G y (2),
  /// u_a = G_e (y - y_hat) + S_21 y_hat (19) and the headway K_h x_2 (S1) when configured and
  /// @p own_state (x_2, m and m/s) is given and finite. A command that overflows stays not finite.
  /// @param y measurement C xi (m, m/s)
  /// @param estimated_output y_hat = C xi_hat (m, m/s)
  /// @param feedforward u_ff, the shared leader acceleration the command takes (m/s^2), or 0
  void compose(const OutputVector& y, const OutputVector& estimated_output,
               const InputVector& feedforward, const StateVector* own_state, Terms* terms) const {
    terms->baseline = baselineCommand<Dims>(baseline_gain_, y);  // (2)
    terms->tracker = tracker_.command(y, estimated_output);      // (19)
    terms->headway_acting = headway_ && own_state != nullptr && own_state->allFinite();
    terms->headway.setZero(input_matrix_.cols());
    if (terms->headway_acting) {  // (S1)
      terms->headway = headway_gain_ * (*own_state);
    }
    terms->saturated = augmentedCommand<Dims>(  // (10)
        terms->baseline, terms->tracker, feedforward,
        terms->headway_acting ? &terms->headway : nullptr, acceleration_limit_, &terms->command);
  }

  /// The augmentation that acts (10) -> (11) (m/s^2): u_a [+ K_h x_2] as composed when neither
  /// sat() nor a rate limit (@p rate_limited) changed the command, else what they left of it,
  /// u_2 - G y - u_ff (actingAugmentation()), with u_2 the command as finally applied.
  InputVector acting(const Terms& terms, const InputVector& command, const InputVector& feedforward,
                     bool rate_limited) const {
    if (terms.saturated || rate_limited) {
      return actingAugmentation(command, terms.baseline, feedforward);
    }
    InputVector augmentation = terms.tracker;
    if (terms.headway_acting) {
      augmentation += terms.headway;
    }
    return augmentation;
  }

  /// The estimator's known drift w of (11) (m/s): B (a_1 - u_ff) (leaderInputDrift()) when the
  /// leader's acceleration @p leader_acceleration is known (not null) and shared into the
  /// estimator, else 0.
  StateVector knownDrift(const InputVector* leader_acceleration,
                         const InputVector& feedforward) const {
    if (leader_acceleration != nullptr && in_estimator_) {
      return leaderInputDrift<Dims>(input_matrix_, *leader_acceleration, feedforward);
    }
    return StateVector::Zero(input_matrix_.rows());
  }

 private:
  CollisionFreeTracker<Dims> tracker_;  // (19)
  double acceleration_limit_;
  bool headway_;                                     // time_headway > 0 (S1)
  bool in_estimator_;                                // leader_information.estimator
  typename Dims::InputMatrix input_matrix_;          // B
  typename Dims::FeedbackGainMatrix baseline_gain_;  // G
  typename Dims::StateGainMatrix headway_gain_;      // K_h (S1)
};

}  // namespace projection_collision_avoidance
