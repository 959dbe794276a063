#pragma once

#include "projection_collision_avoidance/core/AugmentedLaw.hpp"
#include "projection_collision_avoidance/core/BallConstraint.hpp"
#include "projection_collision_avoidance/core/CollisionFreeEstimator.hpp"
#include "projection_collision_avoidance/core/CommandRateLimiter.hpp"
#include "projection_collision_avoidance/core/ConstrainedCommand.hpp"
#include "projection_collision_avoidance/core/ControllerDesign.hpp"
#include "projection_collision_avoidance/core/FollowerControllerStatus.hpp"
#include "projection_collision_avoidance/core/PaperLaws.hpp"
#include "projection_collision_avoidance/core/PlatoonLaws.hpp"
#include "projection_collision_avoidance/core/StepInputs.hpp"
#include "projection_collision_avoidance/core/TypeDefs.hpp"

namespace projection_collision_avoidance {

/// The follower's controller: baseline law (2) augmented (10) by the CF tracker (19), which
/// tracks the CF estimator (11)-(15). One step() per control period T.
///
/// At a tick with measurement y = C xi the command is
///   u_2 = rate(sat(G y + u_a + u_ff [+ K_h x_2])),   u_a = G_e (y - C xi_hat) + S_21 C xi_hat,
/// computed from the current estimate (K_h x_2 the time headway (S1), given the own state x_2;
/// u_ff the shared acceleration, shaped by (S2)), where sat() scales a vector longer than
/// acceleration_limit onto it and rate() moves it to within jerk_limit T of the previous tick's
/// command (CommandRateLimiter; zero before the first tick). The estimate is then integrated
/// over [t, t + T] with y held and the augmentation that actually acts, u_2 - G y - u_ff (u_a
/// [+ K_h x_2] when neither limit acted), so that its model of xi' stays that of the plant. Without
/// a measurement the step runs the fallback, which brakes relative to the leader from the
/// predicted estimate instead, under the same two limits, so that a change of mode cannot jump the
/// command. A step allocates no memory.
///
/// Whatever the inputs, after every call the command is finite with euclideanNorm(u_2) <=
/// acceleration_limit and euclideanNorm(u_2 - u_2 of the previous call) <= jerk_limit T f (f =
/// StepInputs::period_fraction, at most 1: the limit per second of a step less than T after the
/// previous one), and the estimate is finite with euclideanNorm(xi_hat) <= xi_max: a non-finite
/// measurement is treated as missing, a non-finite u_1 as unknown, a command that overflows is
/// replaced by a finite one, and an estimator substep that overflows is discarded; each is
/// flagged in the status.
template <typename Dims>
class FollowerController {
 public:
  using Dimensions = Dims;
  using StateVector = typename Dims::StateVector;
  using InputVector = typename Dims::InputVector;
  using OutputVector = typename Dims::OutputVector;

  /// @param design validated parameters; their sizes must match Dims (std::invalid_argument)
  explicit FollowerController(const ControllerDesign& design)
      : design_(design),
        estimator_(design),
        law_(design),
        input_matrix_(design.parameters.model.B),
        output_matrix_(design.parameters.model.C),
        output_pseudoinverse_(design.output_pseudoinverse),
        fallback_gain_(design.fallback_gain),
        feedforward_filter_(design.parameters.feedforward_gain, design.feedforward_smoothing,
                            design.parameters.model.inputDimension()),
        rate_limiter_(design.parameters.jerk_limit, design.period,
                      design.parameters.acceleration_limit,
                      design.parameters.model.inputDimension()),
        constrained_(design.parameters.acceleration_limit) {
    status_.command = InputVector::Zero(design.parameters.model.inputDimension());
    status_.baseline_command = status_.command;
    status_.tracker_command = status_.command;
    status_.feedforward_command = status_.command;
    status_.headway_command = status_.command;
    status_.fallback_command = status_.command;
    status_.slot_command = status_.command;
    known_feedforward_ = status_.command;
    status_.estimate = estimator_.estimate();
  }

  /// One control period T with what the follower knows at this tick (@p inputs):
  ///
  /// - with a measurement y = C (x_1 - x_2 - d), the laws (2), (19), (10) and the estimator (11);
  ///   a y with a non-finite entry (NaN, +-inf) does not reach them: it counts as missing
  ///   (status.measurement_rejected), and so does a finite y so large that the laws' command
  ///   overflows (status.command_overflow);
  /// - without one (or a y counted as missing), the fallback: the command brakes relative to the
  ///   leader from the estimate, which is predicted by the model alone and stays in Omega_1:
  ///     u_2 = rate(sat(u_ff + K_f xi_hat)),   xi_hat' = Proj(A xi_hat + B (u_1m - u_2)),
  ///   with u_ff and u_1m the leader input as shared into the command and the estimator (0 when
  ///   unknown). For the default K_f = [0, k_v I] of a double integrator the predicted relative
  ///   velocity decays as e^{-k_v t}. Before any measurement the estimate is zero. If u_ff + K_f
  ///   xi_hat overflows (huge gains), the command is u_ff alone (command_overflow).
  ///
  /// A turning slot's acceleration u_r (T3), when given, is a known input: added to the command
  /// in either mode and left out of the augmentation the estimator integrates (in the fallback,
  /// u_2 = rate(sat(u_ff + u_r + K_f xi_hat)) and xi_hat' = Proj(A xi_hat + B (u_1m - u_2 + u_r))),
  /// so that the estimator's model of xi' stays the paper's; a non-finite one is taken as 0
  /// (status.slot_acceleration_rejected).
  ///
  /// The leader's input u_1 (its acceleration a_1) is used as configured by
  /// leader_input_in_command / leader_input_in_estimator; one with a non-finite entry is taken as
  /// unknown for this tick (status.leader_input_rejected). The own state x_2 lets the time
  /// headway (S1) act (time_headway > 0; a non-finite or absent x_2 leaves it out). So the
  /// command is always finite with ||u_2|| <= acceleration_limit (in euclideanNorm()), and the
  /// estimate finite with ||xi_hat|| <= xi_max.
  /// @return the status of this tick; status.command is u_2 (m/s^2 for double integrators)
  const FollowerControllerStatus<Dims>& step(const StepInputs<Dims>& inputs) {
    const bool leader_input_known = inputs.leader_input.has_value();
    period_fraction_ = inputs.period_fraction;
    constraints_ = inputs.command_constraints;
    safety_filter_ = inputs.safety_filter;
    setSlotAcceleration(inputs.slot_acceleration ? &*inputs.slot_acceleration : nullptr);
    return tick(inputs.measurement ? &*inputs.measurement : nullptr,
                leader_input_known ? *inputs.leader_input : InputVector::Zero(input_matrix_.cols()),
                leader_input_known, inputs.own_state ? &*inputs.own_state : nullptr);
  }

  /// Forgets the estimate and the previous command (back to zero, a vehicle at rest); the next
  /// step initialises the estimate as configured.
  void reset() {
    initialized_ = false;
    rate_limiter_.reset();
    feedforward_filter_.reset();
  }

  /// Sets the estimate (projected into Omega_1; zero if not finite) and marks the controller
  /// initialised. The previous command is kept.
  void resetEstimate(const StateVector& estimate) {
    estimator_.reset(estimate);
    initialized_ = true;
  }

  /// False until the first step (or resetEstimate()) has set the estimate.
  bool initialized() const { return initialized_; }

  /// The estimate that the next step will use (m).
  const StateVector& estimate() const { return estimator_.estimate(); }

  /// The command of the last step, from which the next one may change by at most jerk_limit T
  /// (m/s^2 for double integrators); zero before the first step and after reset().
  const InputVector& previousCommand() const { return rate_limiter_.previous(); }

  /// Takes over the estimate (moved into this design's Omega_1, when @p other has one) and the
  /// previous command (moved into ||u|| <= acceleration_limit) of @p other, a controller of the
  /// same sizes with another design: the one way state is carried to a new design.
  void adoptStateOf(const FollowerController& other) {
    rate_limiter_.setPrevious(other.previousCommand());
    if (other.initialized()) {
      resetEstimate(other.estimate());
    }
  }

  const FollowerControllerStatus<Dims>& status() const { return status_; }
  const ControllerDesign& design() const { return design_; }
  const CollisionFreeEstimator<Dims>& estimator() const { return estimator_; }

 private:
  /// One tick: checks the inputs, then runs the laws (y given and finite) or the fallback.
  const FollowerControllerStatus<Dims>& tick(const OutputVector* y, const InputVector& leader_input,
                                             bool leader_input_known,
                                             const StateVector* own_state = nullptr) {
    status_.measurement_rejected = false;
    status_.leader_input_rejected = false;
    status_.command_overflow = false;
    status_.estimate_held = false;
    if (leader_input_known && !leader_input.allFinite()) {
      status_.leader_input_rejected = true;
      leader_input_known = false;
    }
    if (y != nullptr && !y->allFinite()) {
      status_.measurement_rejected = true;
      y = nullptr;
    }
    setFeedforward(leader_input, leader_input_known);
    known_feedforward_ = status_.feedforward_command;
    if (slot_acting_) {
      known_feedforward_ += status_.slot_command;
    }
    if (y != nullptr && advance(*y, leader_input, leader_input_known, own_state)) {
      return status_;
    }
    return fallback(leader_input, leader_input_known);
  }

  /// Initialises the estimate from the finite y as configured.
  void initialize(const OutputVector& y) {
    if (design_.parameters.initial_estimate == InitialEstimate::kZero) {
      estimator_.reset(StateVector::Zero(input_matrix_.rows()));
    } else {
      const StateVector initial = output_pseudoinverse_ * y;
      if (initial.allFinite()) {
        estimator_.reset(initial);
      } else {  // pinv(C) y overflows: keep its direction, scaled
        const double scale = y.cwiseAbs().maxCoeff();
        estimator_.reset(output_pseudoinverse_ * (y / scale), scale);
      }
    }
    initialized_ = true;
  }

  /// The laws for the finite y (AugmentedLaw); false, with nothing changed but the
  /// initialisation and command_overflow set, if their command is not finite.
  bool advance(const OutputVector& y, const InputVector& leader_input, bool leader_input_known,
               const StateVector* own_state) {
    if (!initialized_) {
      initialize(y);
    }
    const StateVector& estimate = estimator_.estimate();
    law_.compose(y, output_matrix_ * estimate, known_feedforward_, own_state, &terms_);
    status_.baseline_command = terms_.baseline;
    status_.tracker_command = terms_.tracker;
    status_.headway_command = terms_.headway;
    status_.command_saturated = terms_.saturated;
    status_.command = terms_.command;
    if (!status_.command.allFinite()) {  // (10) overflowed
      status_.command_overflow = true;
      return false;
    }
    status_.estimate = estimate;
    status_.estimate_norm = euclideanNorm(estimate);
    status_.constraint_value = estimator_.constraint().value(estimate);
    status_.fallback_command.setZero();
    status_.fallback = false;
    status_.command_rate_limited = rate_limiter_.limit(status_.command, period_fraction_);
    const bool projected = constrainCommand();
    const InputVector acting = law_.acting(terms_, status_.command, known_feedforward_,
                                           status_.command_rate_limited || projected);
    const EstimatorPeriodReport report =
        estimator_.advance(y, acting, knownDrift(leader_input, leader_input_known), design_.period,
                           design_.parameters.estimator_substeps);
    status_.projection_active = report.projection_active;
    status_.boundary_correction = report.boundary_correction;
    status_.estimate_held = report.estimate_held;
    return true;
  }

  const FollowerControllerStatus<Dims>& fallback(const InputVector& leader_input,
                                                 bool leader_input_known) {
    const ControllerParameters& p = design_.parameters;
    const StateVector& estimate = estimator_.estimate();
    status_.estimate = estimate;
    status_.estimate_norm = euclideanNorm(estimate);
    status_.constraint_value = estimator_.constraint().value(estimate);
    status_.baseline_command.setZero();
    status_.tracker_command.setZero();
    status_.headway_command.setZero();
    status_.fallback = true;
    status_.fallback_command = fallback_gain_ * estimate;
    status_.command = known_feedforward_ + status_.fallback_command;
    if (!status_.command.allFinite()) {  // K_f xi_hat overflows: u_ff [+ u_r] alone (finite)
      status_.command_overflow = true;
      status_.fallback_command.setZero();
      status_.command = known_feedforward_;
    }
    limitCommand();
    constrainCommand();

    // xi' = A xi + B (u_1 - u_ff) - B (u_2 - u_ff - u_r), with u_1 - u_ff modelled as in step()
    // and u_r the turning slot's acceleration (T3).
    const StateVector drift = knownDrift(leader_input, leader_input_known) -
                              input_matrix_ * (status_.command - known_feedforward_);
    const EstimatorPeriodReport report =
        estimator_.predict(drift, design_.period, p.estimator_substeps);
    status_.projection_active = report.projection_active;
    status_.boundary_correction = report.boundary_correction;
    status_.estimate_held = report.estimate_held;
    return status_;
  }

  /// w of (11) for this tick (AugmentedLaw::knownDrift()).
  StateVector knownDrift(const InputVector& leader_input, bool leader_input_known) const {
    return law_.knownDrift(leader_input_known ? &leader_input : nullptr,
                           status_.feedforward_command);
  }

  /// u_ff of this tick: the shared acceleration, shaped by (S2) when configured; 0 (and the
  /// filter restarted) when it is unknown or not shared into the command.
  void setFeedforward(const InputVector& leader_input, bool leader_input_known) {
    status_.feedforward_command.setZero();
    if (leader_input_known && design_.parameters.leader_input_in_command) {
      status_.feedforward_command =
          feedforward_filter_.shapes() ? feedforward_filter_.apply(leader_input) : leader_input;
    } else {
      feedforward_filter_.reset();
    }
  }

  /// u_r of this tick (T3): the given turning slot's acceleration, 0 when absent or not finite
  /// (slot_acceleration_rejected).
  void setSlotAcceleration(const InputVector* slot_acceleration) {
    status_.slot_acceleration_rejected = false;
    status_.slot_command.setZero();
    slot_acting_ = false;
    if (slot_acceleration != nullptr) {
      if (slot_acceleration->allFinite()) {
        status_.slot_command = *slot_acceleration;
        slot_acting_ = true;
      } else {
        status_.slot_acceleration_rejected = true;
      }
    }
  }
  /// (N3) or (B3) on the command of this step (ConstrainedCommand); true when it moved it.
  bool constrainCommand() {
    return constrained_.apply(constraints_, safety_filter_, &status_, &rate_limiter_);
  }

  /// The fallback's limits: sat() of (10) (saturateCommand(): euclideanNorm(command) <=
  /// acceleration_limit exactly, no overflow), then the change from the previous tick's command
  /// limited to jerk_limit T, inside the same ball.
  void limitCommand() {
    status_.command_saturated =
        saturateCommand(&status_.command, design_.parameters.acceleration_limit);
    status_.command_rate_limited = rate_limiter_.limit(status_.command, period_fraction_);
  }

  ControllerDesign design_;
  CollisionFreeEstimator<Dims> estimator_;
  AugmentedLaw<Dims> law_;                   // (2), (19), (S1), (10) and what of them acts in (11)
  AugmentedTerms<Dims> terms_;               // the latest tick's terms
  typename Dims::InputMatrix input_matrix_;  // B
  typename Dims::OutputMatrix output_matrix_;               // C
  typename Dims::ObserverGainMatrix output_pseudoinverse_;  // pinv(C)
  typename Dims::StateGainMatrix fallback_gain_;            // K_f
  FeedforwardFilter<InputVector> feedforward_filter_;       // (S2)
  CommandRateLimiter<InputVector> rate_limiter_;            // jerk_limit, from u_2(k-1)
  ConstrainedCommand<Dims> constrained_;                    // (N3), (B3)
  FollowerControllerStatus<Dims> status_;
  InputVector known_feedforward_;  // u_ff + u_r: the command's known inputs of this tick
  bool slot_acting_ = false;       // u_r given at this step
  double period_fraction_ = 1.0;   // of this step (StepInputs::period_fraction)
  const CommandProjection* constraints_ = nullptr;  // of this step (StepInputs)
  const SafetyFilter* safety_filter_ = nullptr;     // of this step (StepInputs)
  bool initialized_ = false;
};

extern template class FollowerController<DoubleIntegrator1D>;
extern template class FollowerController<DoubleIntegrator2D>;
extern template class FollowerController<DoubleIntegrator3D>;
extern template class FollowerController<GenericDimensions>;

}  // namespace projection_collision_avoidance
