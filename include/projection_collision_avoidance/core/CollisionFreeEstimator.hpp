#pragma once

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "projection_collision_avoidance/core/BallConstraint.hpp"
#include "projection_collision_avoidance/core/ControllerDesign.hpp"
#include "projection_collision_avoidance/core/PaperLaws.hpp"
#include "projection_collision_avoidance/core/ProjectionOperator.hpp"
#include "projection_collision_avoidance/core/TypeDefs.hpp"

namespace projection_collision_avoidance {

/// What happened to the estimate over one control period.
struct EstimatorPeriodReport {
  bool projection_active = false;    ///< the projection changed the drift in some substep
  double boundary_correction = 0.0;  ///< largest distance (m) by which a substep's result was
                                     ///< moved back onto the sphere ||xi_hat|| = xi_max
  /// A substep's result (or the held input itself) was not finite, an overflow with huge finite
  /// inputs or gains: the estimate was held at its value before that substep for the rest of the
  /// period.
  bool estimate_held = false;
};

/// The collision-free (CF) estimator: a Luenberger observer of the relative error xi whose drift
/// (11) is wrapped in the Gamma-weighted projection operator, so that ||xi_hat|| <= xi_max.
///
/// Between two control ticks the measurement y and the tracker input u_a are held; the estimate
/// is integrated with classical Runge-Kutta (RK4) substeps of the projected drift. The flow
/// keeps Omega_1 invariant; RK4 can leave it by its local truncation error (order h^5), and any
/// such excess is removed by scaling the estimate back onto the sphere (16 ulps inside it), so
/// ||xi_hat|| <= xi_max holds exactly after every substep, in any evaluation of the norm. The
/// size of that correction is reported. The estimate is always finite: a substep whose result is
/// not (an overflow with huge finite inputs or gains) is discarded and the estimate held, which
/// the report says.
template <typename Dims>
class CollisionFreeEstimator {
 public:
  using StateVector = typename Dims::StateVector;
  using InputVector = typename Dims::InputVector;
  using OutputVector = typename Dims::OutputVector;
  using StateMatrix = typename Dims::StateMatrix;
  using InputMatrix = typename Dims::InputMatrix;
  using ObserverGainMatrix = typename Dims::ObserverGainMatrix;

  /// @param design validated parameters; their sizes must match Dims (std::invalid_argument)
  explicit CollisionFreeEstimator(const ControllerDesign& design)
      : constraint_(design.xi_max, design.parameters.epsilon) {
    if (!Dims::fits(design.parameters.model.stateDimension(),
                    design.parameters.model.inputDimension(),
                    design.parameters.model.outputDimension())) {
      throw std::invalid_argument("CollisionFreeEstimator: model sizes do not fit the dimensions");
    }
    estimator_matrix_ = design.estimator_matrix;
    state_matrix_ = design.parameters.model.A;
    input_matrix_ = design.parameters.model.B;
    observer_gain_ = design.parameters.estimator_gain;
    gamma_inverse_ = design.gamma_inverse;
    estimate_ = StateVector::Zero(design.parameters.model.stateDimension());
  }

  /// Sets the estimate, scaled into Omega_1 if it lies outside; zero if it is not finite.
  void reset(const StateVector& estimate) {
    estimate_ = estimate;
    if (!estimate_.allFinite()) {
      estimate_.setZero();
    }
    moveIntoBound(&estimate_);
  }

  /// Sets the estimate to scale * direction (scale >= 0), scaled into Omega_1 if it lies
  /// outside, also when that product overflows: then it is put on the sphere along direction.
  /// Zero if direction or scale is not finite.
  void reset(const StateVector& direction, double scale) {
    estimate_ = scale * direction;
    if (estimate_.allFinite()) {
      moveIntoBound(&estimate_);
      return;
    }
    if (!direction.allFinite() || !std::isfinite(scale)) {
      estimate_.setZero();
      return;
    }
    // ||scale direction|| > DBL_MAX: outside any representable ball. On the sphere (or, for an
    // unbounded Omega_1, a sphere of representable radius) along the direction.
    estimate_ = direction / direction.cwiseAbs().maxCoeff();
    estimate_ /= euclideanNorm(estimate_);
    estimate_ *= std::min(constraint_.hardRadius(), 0.25 * kLargest);
    moveIntoBound(&estimate_);
  }

  /// The current estimate xi_hat (m).
  const StateVector& estimate() const { return estimate_; }

  const BallConstraint& constraint() const { return constraint_; }

  /// The held part c = w - B u_a - L y of the unprojected drift (11), estimatorHeldInput(): h =
  /// A_c xi_hat - B u_a + L (C xi_hat - y) + w = (A_c + L C) xi_hat + c (estimatorDrift()).
  /// @param w known input drift (m/s), B (u_1 - u_ff) when the leader's input is shared
  ///        (leaderInputDrift()), else 0
  StateVector heldInput(const OutputVector& y, const InputVector& tracker_input,
                        const StateVector& w) const {
    return estimatorHeldInput<Dims>(input_matrix_, observer_gain_, y, tracker_input, w);
  }

  /// Projected derivative xi_hat' at @p estimate for the held input c (m/s).
  StateVector derivative(const StateVector& estimate, const StateVector& held_input,
                         bool* active) const {
    return projectedDerivative(estimator_matrix_, estimate, held_input, active);
  }

  /// Advances the estimate over one control period with y and u_a held (15).
  /// @param y relative measurement C xi at the start of the period
  /// @param tracker_input the augmentation that acts over the period (m/s^2): u_a, or
  ///        actingAugmentation() when a limit cut the command
  /// @param w known input drift (m/s), see heldInput()
  /// @param period control period T (s), > 0
  /// @param substeps number of RK4 steps, >= 1
  EstimatorPeriodReport advance(const OutputVector& y, const InputVector& tracker_input,
                                const StateVector& w, double period, int substeps) {
    return integrate(estimator_matrix_, heldInput(y, tracker_input, w), period, substeps);
  }

  /// Predicts the estimate over one control period without a measurement (the fallback): the
  /// model's own dynamics, projected, xi_hat' = Proj(A xi_hat + w), with w held. The
  /// correction L (C xi_hat - y) of (11) is absent, so the estimate stays in Omega_1.
  /// @param w held input drift (m/s): B (u_1 - u_2) with the leader's input as far as known
  /// @param period control period T (s), > 0
  /// @param substeps number of RK4 steps, >= 1
  EstimatorPeriodReport predict(const StateVector& w, double period, int substeps) {
    return integrate(state_matrix_, w, period, substeps);
  }

 private:
  StateVector projectedDerivative(const StateMatrix& F, const StateVector& estimate,
                                  const StateVector& held_input, bool* active) const {
    const StateVector drift = estimatorDrift<Dims>(F, estimate, held_input);
    return projectDrift(constraint_, estimate, drift, gamma_inverse_, active);
  }

  /// RK4 over one period of xi_hat' = Proj(F xi_hat + c), c held; after each substep the
  /// estimate is moved back into Omega_1 if the substep's truncation error left it outside. A
  /// substep whose result is not finite is discarded, and the estimate held from there on.
  EstimatorPeriodReport integrate(const StateMatrix& F, const StateVector& c, double period,
                                  int substeps) {
    EstimatorPeriodReport report;
    if (!c.allFinite()) {
      report.estimate_held = true;
      return report;
    }
    bool* active = &report.projection_active;
    const double h = period / substeps;
    for (int i = 0; i < substeps; ++i) {
      const StateVector k1 = projectedDerivative(F, estimate_, c, active);
      const StateVector k2 = projectedDerivative(F, estimate_ + (0.5 * h) * k1, c, active);
      const StateVector k3 = projectedDerivative(F, estimate_ + (0.5 * h) * k2, c, active);
      const StateVector k4 = projectedDerivative(F, estimate_ + h * k3, c, active);
      StateVector next = estimate_ + (h / 6.0) * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
      if (!next.allFinite()) {
        report.estimate_held = true;
        break;  // c is held: every further substep from here would overflow alike
      }
      const double correction = moveIntoBound(&next);
      report.boundary_correction = std::max(report.boundary_correction, correction);
      estimate_ = next;
    }
    return report;
  }

  /// Scales the finite @p x onto the sphere of radius xi_max (1 - kBoundMargin) if it lies
  /// outside (clampNorm()); returns the distance moved (m), infinite if ||x|| exceeds DBL_MAX.
  /// The margin, 16 ulps relative, covers the rounding of any order of summing ||x||^2 (up to 12
  /// entries), so that ||xi_hat|| <= xi_max holds however the norm is evaluated (Eigen's norm()
  /// sums fixed- and dynamic-size vectors in different orders).
  double moveIntoBound(StateVector* x) const {
    const double radius = constraint_.hardRadius() * (1.0 - kBoundMargin);
    const double norm = clampNorm(*x, radius);
    return norm > 0.0 ? norm - radius : 0.0;
  }

  static constexpr double kBoundMargin = 16.0 * std::numeric_limits<double>::epsilon();
  static constexpr double kLargest = std::numeric_limits<double>::max();

  BallConstraint constraint_;
  StateMatrix estimator_matrix_;      // A_c + L C
  StateMatrix state_matrix_;          // A
  InputMatrix input_matrix_;          // B
  ObserverGainMatrix observer_gain_;  // L
  StateMatrix gamma_inverse_;         // Gamma^-1
  StateVector estimate_;
};

}  // namespace projection_collision_avoidance
