#include "projection_collision_avoidance/sim/AgentIntegrator.hpp"

#include <cmath>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "projection_collision_avoidance/core/ExactDiscretization.hpp"

namespace projection_collision_avoidance {
namespace {

/// Throws std::invalid_argument unless @p size fits a dimension of compile-time size @p fixed
/// (Eigen::Dynamic: any size from 1 to @p max).
void requireDimension(const char* what, Eigen::Index size, int fixed, int max) {
  const bool fits = fixed == Eigen::Dynamic ? (size >= 1 && size <= max) : size == fixed;
  if (!fits) {
    throw std::invalid_argument(std::string("AgentIntegrator: ") + what + " of size " +
                                std::to_string(size) + " does not fit the dimensions");
  }
}

}  // namespace

template <typename Dims>
AgentIntegrator<Dims>::AgentIntegrator(const AgentModel& model, double nominal_step,
                                       const Eigen::Ref<const Eigen::VectorXd>& initial_state,
                                       SignalProfile disturbance)
    : state_matrix_(model.A),
      nominal_step_(nominal_step),
      disturbance_(std::move(disturbance)),
      disturbed_(!disturbance_.pulses.empty() || !disturbance_.sinusoids.empty()) {
  const Eigen::Index n = model.A.rows();
  requireDimension("A", n, Dims::kStates, Dims::kMaxStates);
  requireDimension("B", model.B.cols(), Dims::kInputs, Dims::kMaxInputs);
  if (model.A.cols() != n || model.B.rows() != n) {
    throw std::invalid_argument("AgentIntegrator: A must be n x n and B n x m");
  }
  if (!(std::isfinite(nominal_step) && nominal_step > 0.0)) {
    throw std::invalid_argument("AgentIntegrator: the nominal step must be finite and > 0, got " +
                                std::to_string(nominal_step));
  }
  for (const Pulse& pulse : disturbance_.pulses) {
    if (pulse.vector.size() != n) {
      throw std::invalid_argument("AgentIntegrator: a disturbance pulse must have n entries");
    }
  }
  for (const Sinusoid& wave : disturbance_.sinusoids) {
    if (wave.amplitude.size() != n) {
      throw std::invalid_argument("AgentIntegrator: a disturbance sinusoid must have n entries");
    }
  }
  input_matrix_ = model.B;
  const ExactDiscretization nominal = ExactDiscretization::compute(model.A, nominal_step);
  transition_ = nominal.transition;
  integral_ = nominal.integral;
  setState(initial_state);
}

template <typename Dims>
void AgentIntegrator<Dims>::setState(const Eigen::Ref<const Eigen::VectorXd>& state) {
  if (state.size() != state_matrix_.rows()) {
    throw std::invalid_argument("AgentIntegrator: the state must have " +
                                std::to_string(state_matrix_.rows()) + " entries, got " +
                                std::to_string(state.size()));
  }
  state_ = state;
}

template <typename Dims>
Eigen::VectorXd AgentIntegrator<Dims>::disturbanceAt(double t) const {
  return disturbance_.value(t, state_matrix_.rows());
}

template <typename Dims>
void AgentIntegrator<Dims>::advance(double t, double dt, const InputVector& input) {
  if (!(std::isfinite(dt) && dt >= 0.0)) {
    throw std::invalid_argument("AgentIntegrator: the step must be finite and >= 0, got " +
                                std::to_string(dt));
  }
  if (dt == 0.0) {
    return;
  }
  const StateVector drive = input_matrix_ * input;
  const double t_end = t + dt;
  // Split the step at the disturbance's pulse edges; evaluate w mid-segment so that an edge that
  // rounding puts a hair away from a tick does not flip the pulse's state.
  const double tolerance = 1e-9 * dt;
  if (!disturbance_.hasEdgeWithin(t + tolerance, t_end - tolerance)) {
    if (dt == nominal_step_) {
      advanceSegment(t, t_end, transition_, integral_, drive);
    } else {
      advanceUncached(t, t_end, drive);
    }
    return;
  }
  double a = t;
  for (const double edge : disturbance_.edgesWithin(t + tolerance, t_end - tolerance)) {
    advanceUncached(a, edge, drive);
    a = edge;
  }
  advanceUncached(a, t_end, drive);
}

template <typename Dims>
template <typename Matrix>
void AgentIntegrator<Dims>::advanceSegment(double a, double b, const Matrix& transition,
                                           const Matrix& integral, const StateVector& drive) {
  if (disturbed_) {
    StateVector w = drive;
    disturbance_.addTo(0.5 * (a + b), w);
    state_ = transition * state_ + integral * w;
  } else {
    state_ = transition * state_ + integral * drive;
  }
}

template <typename Dims>
void AgentIntegrator<Dims>::advanceUncached(double a, double b, const StateVector& drive) {
  const ExactDiscretization segment = ExactDiscretization::compute(state_matrix_, b - a);
  advanceSegment(a, b, segment.transition, segment.integral, drive);
}

template class AgentIntegrator<DoubleIntegrator1D>;
template class AgentIntegrator<DoubleIntegrator2D>;
template class AgentIntegrator<DoubleIntegrator3D>;
template class AgentIntegrator<GenericDimensions>;

}  // namespace projection_collision_avoidance
