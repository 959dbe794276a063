#pragma once

#include <Eigen/Core>

#include "projection_collision_avoidance/core/AgentModel.hpp"
#include "projection_collision_avoidance/core/TypeDefs.hpp"
#include "projection_collision_avoidance/sim/SignalProfile.hpp"

namespace projection_collision_avoidance {

/// One agent x' = A x + B u + w(t), integrated exactly over a step [t, t + dt] with the input u
/// held (zero-order hold) and w(t) a disturbance profile (the leader's u_d; none for a follower).
///
/// Over a segment of length delta with v = B u + w constant, x <- Phi(delta) x + Psi(delta) v
/// (ExactDiscretization). The step is split at the disturbance's pulse edges strictly inside it
/// (edges within 1e-9 dt of either end are taken as on the tick) and w is evaluated at the middle
/// of each segment, so a pulse acts exactly over [start, end) and an edge that rounding puts a
/// hair away from a tick does not flip it. Sinusoids in the profile (the scenario format gives
/// the disturbance none) are taken at their mid-segment value. Phi and Psi of the nominal step
/// are computed once; an unsplit nominal step allocates no memory.
///
/// Instantiated for DoubleIntegrator1D, 2D, 3D and GenericDimensions.
template <typename Dims>
class AgentIntegrator {
 public:
  using StateVector = typename Dims::StateVector;
  using InputVector = typename Dims::InputVector;

  /// @param model A (n x n) and B (n x m); n, m must fit Dims
  /// @param nominal_step dt (s), finite and > 0, whose Phi and Psi are cached
  /// @param initial_state x(0) (n entries; m and m/s for a double integrator)
  /// @param disturbance w(t) (n entries per vector; position-rate part in m/s, then
  ///        velocity-rate part in m/s^2 for a double integrator); empty for none
  /// @throws std::invalid_argument for sizes that do not match or a step that is not > 0
  AgentIntegrator(const AgentModel& model, double nominal_step,
                  const Eigen::Ref<const Eigen::VectorXd>& initial_state,
                  SignalProfile disturbance = {});

  /// The current state x.
  const StateVector& state() const { return state_; }

  /// Replaces the state (n entries). @throws std::invalid_argument for a wrong size
  void setState(const Eigen::Ref<const Eigen::VectorXd>& state);

  /// The step dt (s) whose discretisation is cached.
  double nominalStep() const { return nominal_step_; }

  /// The disturbance w(t).
  const SignalProfile& disturbance() const { return disturbance_; }

  /// w(t) (n entries): the disturbance at time @p t (s).
  Eigen::VectorXd disturbanceAt(double t) const;

  /// Integrates from @p t to t + nominalStep() (s) with @p input held.
  /// @param t start of the step (s); only the disturbance depends on it
  /// @param input u (m entries; m/s^2 for a double integrator)
  void advance(double t, const InputVector& input) { advance(t, nominal_step_, input); }

  /// Integrates from @p t to t + @p dt (s) with @p input held. A dt other than nominalStep()
  /// is discretised for itself; dt = 0 leaves the state unchanged.
  /// @throws std::invalid_argument unless dt is finite and >= 0
  void advance(double t, double dt, const InputVector& input);

 private:
  /// x <- transition x + integral (drive + w(mid-segment)) over [a, b].
  template <typename Matrix>
  void advanceSegment(double a, double b, const Matrix& transition, const Matrix& integral,
                      const StateVector& drive);

  /// [a, b], a part of a step cut at a pulse edge or a step of another length.
  void advanceUncached(double a, double b, const StateVector& drive);

  Eigen::MatrixXd state_matrix_;             // A, for the discretisation of other step lengths
  typename Dims::InputMatrix input_matrix_;  // B
  double nominal_step_;
  typename Dims::StateMatrix transition_;  // Phi(nominal step)
  typename Dims::StateMatrix integral_;    // Psi(nominal step) (s)
  SignalProfile disturbance_;
  bool disturbed_;
  StateVector state_;
};

extern template class AgentIntegrator<DoubleIntegrator1D>;
extern template class AgentIntegrator<DoubleIntegrator2D>;
extern template class AgentIntegrator<DoubleIntegrator3D>;
extern template class AgentIntegrator<GenericDimensions>;

}  // namespace projection_collision_avoidance
