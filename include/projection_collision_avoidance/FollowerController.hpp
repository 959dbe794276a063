#pragma once

#include "projection_collision_avoidance/CollisionFreeEstimator.hpp"
#include "projection_collision_avoidance/CollisionFreeTracker.hpp"
#include "projection_collision_avoidance/ControllerDesign.hpp"
#include "projection_collision_avoidance/TypeDefs.hpp"

namespace projection_collision_avoidance {

/// Everything the follower computed at one control tick.
template <typename Dims>
struct FollowerControllerStatus {
  typename Dims::InputVector command;  ///< u_2 = baseline + tracker + feed-forward, saturated
  typename Dims::InputVector baseline_command;     ///< G y (2)
  typename Dims::InputVector tracker_command;      ///< u_a (19)
  typename Dims::InputVector feedforward_command;  ///< u_1 when shared into the command, else 0
  typename Dims::StateVector estimate;             ///< xi_hat used at this tick (m)
  double estimate_norm = 0.0;                      ///< ||xi_hat|| (m)
  double constraint_value = 0.0;                   ///< f(xi_hat) (13)
  bool command_saturated = false;    ///< the sum exceeded acceleration_limit and was scaled
  bool projection_active = false;    ///< the projection acted during the period that follows
  double boundary_correction = 0.0;  ///< see EstimatorPeriodReport (m)
};

/// The follower's controller: baseline law (2) augmented (10) by the CF tracker (19), which
/// tracks the CF estimator (11)-(15). One step() per control period T.
///
/// At a tick with measurement y = C xi the command is
///   u_2 = sat(G y + u_a + u_ff),   u_a = G_e (y - C xi_hat) + S_21 C xi_hat,
/// computed from the current estimate, where sat() scales a vector longer than
/// acceleration_limit onto it. The estimate is then integrated over [t, t + T] with y held and
/// the augmentation that actually acts, u_2 - G y - u_ff (u_a when not saturated), so that its
/// model of xi' stays that of the plant. A step allocates no memory.
template <typename Dims>
class FollowerController {
 public:
  using StateVector = typename Dims::StateVector;
  using InputVector = typename Dims::InputVector;
  using OutputVector = typename Dims::OutputVector;

  /// @param design validated parameters; their sizes must match Dims (std::invalid_argument)
  explicit FollowerController(const ControllerDesign& design)
      : design_(design),
        estimator_(design),
        tracker_(design),
        input_matrix_(design.parameters.model.B),
        output_matrix_(design.parameters.model.C),
        baseline_gain_(design.parameters.baseline_gain),
        output_pseudoinverse_(design.output_pseudoinverse) {
    status_.command = InputVector::Zero(design.parameters.model.inputDimension());
    status_.baseline_command = status_.command;
    status_.tracker_command = status_.command;
    status_.feedforward_command = status_.command;
    status_.estimate = estimator_.estimate();
  }

  /// One control period without leader information (u_1 taken as unknown).
  /// @param y relative measurement C (x_1 - x_2 - d), finite
  /// @return the status of this tick; status.command is u_2 (m/s^2 for double integrators)
  const FollowerControllerStatus<Dims>& step(const OutputVector& y) {
    return advance(y, InputVector::Zero(input_matrix_.cols()), false);
  }

  /// One control period with the leader's current input u_1 (used as configured by
  /// leader_input_in_command / leader_input_in_estimator).
  const FollowerControllerStatus<Dims>& step(const OutputVector& y,
                                             const InputVector& leader_input) {
    return advance(y, leader_input, true);
  }

  /// Forgets the estimate; the next step initialises it as configured.
  void reset() { initialized_ = false; }

  /// Sets the estimate (projected into Omega_1) and marks the controller initialised.
  void resetEstimate(const StateVector& estimate) {
    estimator_.reset(estimate);
    initialized_ = true;
  }

  /// False until the first step (or resetEstimate()) has set the estimate.
  bool initialized() const { return initialized_; }

  /// The estimate that the next step will use (m).
  const StateVector& estimate() const { return estimator_.estimate(); }
  const FollowerControllerStatus<Dims>& status() const { return status_; }
  const ControllerDesign& design() const { return design_; }
  const CollisionFreeEstimator<Dims>& estimator() const { return estimator_; }

 private:
  const FollowerControllerStatus<Dims>& advance(const OutputVector& y,
                                                const InputVector& leader_input,
                                                bool leader_input_known) {
    const ControllerParameters& p = design_.parameters;
    if (!initialized_) {
      if (p.initial_estimate == InitialEstimate::kMeasurement) {
        estimator_.reset(output_pseudoinverse_ * y);
      } else {
        estimator_.reset(StateVector::Zero(input_matrix_.rows()));
      }
      initialized_ = true;
    }
    const StateVector& estimate = estimator_.estimate();
    const OutputVector estimated_output = output_matrix_ * estimate;

    status_.estimate = estimate;
    status_.estimate_norm = estimate.norm();
    status_.constraint_value = estimator_.constraint().value(estimate);
    status_.baseline_command = baseline_gain_ * y;
    status_.tracker_command = tracker_.command(y, estimated_output);
    status_.feedforward_command.setZero();
    if (leader_input_known && p.leader_input_in_command) {
      status_.feedforward_command = leader_input;
    }
    status_.command =
        status_.baseline_command + status_.tracker_command + status_.feedforward_command;
    const double norm = status_.command.norm();
    status_.command_saturated = norm > p.acceleration_limit;
    InputVector acting_augmentation = status_.tracker_command;
    if (status_.command_saturated) {
      status_.command *= p.acceleration_limit / norm;
      acting_augmentation =
          status_.command - status_.baseline_command - status_.feedforward_command;
    }

    StateVector known_drift = StateVector::Zero(input_matrix_.rows());
    if (leader_input_known && p.leader_input_in_estimator) {
      known_drift = input_matrix_ * (leader_input - status_.feedforward_command);
    }
    const EstimatorPeriodReport report = estimator_.advance(y, acting_augmentation, known_drift,
                                                            design_.period, p.estimator_substeps);
    status_.projection_active = report.projection_active;
    status_.boundary_correction = report.boundary_correction;
    return status_;
  }

  ControllerDesign design_;
  CollisionFreeEstimator<Dims> estimator_;
  CollisionFreeTracker<Dims> tracker_;
  typename Dims::InputMatrix input_matrix_;                 // B
  typename Dims::OutputMatrix output_matrix_;               // C
  typename Dims::FeedbackGainMatrix baseline_gain_;         // G
  typename Dims::ObserverGainMatrix output_pseudoinverse_;  // pinv(C)
  FollowerControllerStatus<Dims> status_;
  bool initialized_ = false;
};

extern template class FollowerController<DoubleIntegrator1D>;
extern template class FollowerController<DoubleIntegrator2D>;
extern template class FollowerController<DoubleIntegrator3D>;
extern template class FollowerController<GenericDimensions>;

}  // namespace projection_collision_avoidance
