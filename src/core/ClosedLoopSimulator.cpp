#include "projection_collision_avoidance/ClosedLoopSimulator.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <locale>
#include <sstream>
#include <string>
#include <vector>

#include "projection_collision_avoidance/ControllerDesign.hpp"
#include "projection_collision_avoidance/DimensionDispatch.hpp"
#include "projection_collision_avoidance/ExactDiscretization.hpp"
#include "projection_collision_avoidance/FollowerController.hpp"

namespace projection_collision_avoidance {
namespace {

/// Both agents of the run, integrated exactly with their inputs held over each step.
template <typename Dims>
class TwoAgentPlant {
 public:
  using StateVector = typename Dims::StateVector;
  using InputVector = typename Dims::InputVector;

  TwoAgentPlant(const Scenario& scenario, double period)
      : model_(scenario.controller.model),
        disturbance_(scenario.disturbance),
        period_(period),
        input_matrix_(scenario.controller.model.B),
        leader_(scenario.leader_initial_state),
        follower_(scenario.follower_initial_state) {
    const ExactDiscretization nominal = ExactDiscretization::compute(model_.A, period);
    transition_ = nominal.transition;
    integral_ = nominal.integral;
  }

  const StateVector& leader() const { return leader_; }
  const StateVector& follower() const { return follower_; }

  /// Integrates both agents from t to t + period with u_1, u_2 held and u_d exact.
  void advance(double t, const InputVector& leader_input, const InputVector& follower_input) {
    const StateVector leader_drive = input_matrix_ * leader_input;
    const StateVector follower_drive = input_matrix_ * follower_input;
    // Split the step at the disturbance's pulse edges; evaluate u_d mid-segment so that an
    // edge that rounding puts a hair away from a tick does not flip the pulse's state.
    const double t_end = t + period_;
    const double tolerance = 1e-9 * period_;
    const std::vector<double> edges = disturbance_.edgesWithin(t + tolerance, t_end - tolerance);
    if (edges.empty()) {
      advanceSegment(t, t_end, transition_, integral_, leader_drive, follower_drive);
      return;
    }
    double a = t;
    for (const double edge : edges) {
      advanceSplit(a, edge, leader_drive, follower_drive);
      a = edge;
    }
    advanceSplit(a, t_end, leader_drive, follower_drive);
  }

 private:
  /// Integrates over [a, b] with the discretisation (Phi, Psi) of that interval.
  template <typename Matrix>
  void advanceSegment(double a, double b, const Matrix& transition, const Matrix& integral,
                      const StateVector& leader_drive, const StateVector& follower_drive) {
    StateVector w = leader_drive;
    if (!disturbance_.pulses.empty()) {
      w += disturbance_.value(0.5 * (a + b), model_.stateDimension());
    }
    leader_ = transition * leader_ + integral * w;
    follower_ = transition * follower_ + integral * follower_drive;
  }

  /// A part of a period cut at a pulse edge: discretised for its own length.
  void advanceSplit(double a, double b, const StateVector& leader_drive,
                    const StateVector& follower_drive) {
    const ExactDiscretization segment = ExactDiscretization::compute(model_.A, b - a);
    advanceSegment(a, b, segment.transition, segment.integral, leader_drive, follower_drive);
  }

  const AgentModel& model_;
  const SignalProfile& disturbance_;
  double period_;
  typename Dims::StateMatrix transition_;    // Phi over one period
  typename Dims::StateMatrix integral_;      // Psi over one period
  typename Dims::InputMatrix input_matrix_;  // B
  StateVector leader_;
  StateVector follower_;
};

template <typename Dims>
SimulationSummary runClosedLoop(const Scenario& scenario, const ControllerDesign& design,
                                const SampleObserver& observer) {
  using StateVector = typename Dims::StateVector;
  using InputVector = typename Dims::InputVector;
  using OutputVector = typename Dims::OutputVector;
  const ControllerParameters& p = design.parameters;
  const AgentModel& model = p.model;
  const Eigen::Index m = model.inputDimension();
  const Eigen::Index n = model.stateDimension();
  const int k = model.position_dimension;
  const bool share_leader_input = p.leader_input_in_command || p.leader_input_in_estimator;

  FollowerController<Dims> controller(design);
  TwoAgentPlant<Dims> plant(scenario, design.period);
  const StateVector separation = p.separation;
  const typename Dims::OutputMatrix output_matrix = model.C;

  SimulationSummary summary;
  summary.xi_max = design.xi_max;
  summary.perimeter = design.perimeter;
  summary.min_separation = std::numeric_limits<double>::infinity();
  const long last_tick = std::lround(scenario.duration * p.control_rate);
  for (long tick = 0; tick <= last_tick; ++tick) {
    const double t = static_cast<double>(tick) / p.control_rate;
    const StateVector xi = plant.leader() - plant.follower() - separation;
    const OutputVector y = output_matrix * xi;
    const InputVector leader_input = scenario.leader_input.value(t, m);
    const auto& status = share_leader_input ? controller.step(y, leader_input) : controller.step(y);

    const double xi_norm = xi.norm();
    const double separation_distance = (plant.leader() - plant.follower()).head(k).norm();
    summary.max_xi = std::max(summary.max_xi, xi_norm);
    summary.max_xi_hat = std::max(summary.max_xi_hat, status.estimate_norm);
    summary.min_separation = std::min(summary.min_separation, separation_distance);
    summary.max_boundary_correction =
        std::max(summary.max_boundary_correction, status.boundary_correction);
    if (xi_norm > design.xi_max) {
      summary.time_outside += design.period;
    }
    ++summary.ticks;

    if (observer) {
      SimulationSample sample;
      sample.time = t;
      sample.relative_error = xi;
      sample.estimate = status.estimate;
      sample.constraint_value = status.constraint_value;
      sample.projection_active = status.projection_active;
      sample.leader_state = plant.leader();
      sample.follower_state = plant.follower();
      sample.separation = separation_distance;
      sample.command = status.command;
      sample.baseline_command = status.baseline_command;
      sample.tracker_command = status.tracker_command;
      sample.leader_input = leader_input;
      sample.disturbance = scenario.disturbance.value(t, n);
      observer(sample);
    }
    if (tick < last_tick) {
      plant.advance(t, leader_input, status.command);
    }
  }
  return summary;
}

}  // namespace

SimulationSummary simulate(const Scenario& scenario, const SampleObserver& observer) {
  const ControllerDesign design = ControllerDesign::create(scenario.controller);
  scenario.validate();
  return visitDimensions(scenario.controller.model, [&](auto dims) {
    return runClosedLoop<decltype(dims)>(scenario, design, observer);
  });
}

std::string formatSummary(const SimulationSummary& summary, double wall_seconds) {
  // A stream in the classic locale with precision 9 and the default float format prints each
  // value exactly as printf's "%.9g" does, without a C varargs call.
  std::ostringstream line;
  line.imbue(std::locale::classic());
  line.precision(9);
  line << "max_xi=" << summary.max_xi << " max_xi_hat=" << summary.max_xi_hat
       << " xi_max=" << summary.xi_max << " min_separation=" << summary.min_separation
       << " time_outside=" << summary.time_outside << " wall_s=" << wall_seconds;
  return line.str();
}

}  // namespace projection_collision_avoidance
