#include "projection_collision_avoidance/ClosedLoopSimulator.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <locale>
#include <sstream>
#include <string>

#include "projection_collision_avoidance/AgentIntegrator.hpp"
#include "projection_collision_avoidance/ControllerDesign.hpp"
#include "projection_collision_avoidance/DimensionDispatch.hpp"
#include "projection_collision_avoidance/FollowerController.hpp"

namespace projection_collision_avoidance {
namespace {

/// Both agents of the run, each integrated exactly with its input held over each period; the
/// leader also under the disturbance u_d (applied exactly, the period split at its pulse edges).
template <typename Dims>
class TwoAgentPlant {
 public:
  using StateVector = typename Dims::StateVector;
  using InputVector = typename Dims::InputVector;

  TwoAgentPlant(const Scenario& scenario, double period)
      : leader_(scenario.controller.model, period, scenario.leader_initial_state,
                scenario.disturbance),
        follower_(scenario.controller.model, period, scenario.follower_initial_state) {}

  const StateVector& leader() const { return leader_.state(); }
  const StateVector& follower() const { return follower_.state(); }

  /// Integrates both agents from t to t + period with u_1, u_2 held and u_d exact.
  void advance(double t, const InputVector& leader_input, const InputVector& follower_input) {
    leader_.advance(t, leader_input);
    follower_.advance(t, follower_input);
  }

 private:
  AgentIntegrator<Dims> leader_;
  AgentIntegrator<Dims> follower_;
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
    const StateVector offset = plant.leader() - plant.follower();
    double separation_squared = 0.0;  // ||p_1 - p_2||^2 over the k position entries
    for (int i = 0; i < k; ++i) {
      separation_squared += offset(i) * offset(i);
    }
    const double separation_distance = std::sqrt(separation_squared);
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
