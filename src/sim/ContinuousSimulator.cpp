#include "projection_collision_avoidance/sim/ContinuousSimulator.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "projection_collision_avoidance/core/ControllerDesign.hpp"
#include "projection_collision_avoidance/core/DimensionDispatch.hpp"
#include "projection_collision_avoidance/core/Formation.hpp"
#include "projection_collision_avoidance/core/ParameterError.hpp"
#include "projection_collision_avoidance/sim/ContinuousDynamics.hpp"

namespace projection_collision_avoidance {
namespace {

/// @p v (n entries) as a vector of the bounded type, copied entry by entry.
template <typename Vector>
Vector toBounded(const Eigen::VectorXd& v) {
  Vector result = Vector::Zero(v.size());
  for (Eigen::Index i = 0; i < result.size(); ++i) {
    result(i) = v(i);
  }
  return result;
}

/// No segment: the pulses must be taken afresh.
constexpr std::size_t kNoSegment = std::numeric_limits<std::size_t>::max();

/// Classical Runge-Kutta, 4 stages, order 4.
struct ClassicalRungeKutta4 {
  static constexpr int kStages = 4;
  static constexpr std::array<double, kStages> c = {0.0, 0.5, 0.5, 1.0};
  static constexpr std::array<std::array<double, kStages>, kStages> a = {{
      {0.0, 0.0, 0.0, 0.0},
      {0.5, 0.0, 0.0, 0.0},
      {0.0, 0.5, 0.0, 0.0},
      {0.0, 0.0, 1.0, 0.0},
  }};
  static constexpr std::array<double, kStages> b = {1.0 / 6.0, 1.0 / 3.0, 1.0 / 3.0, 1.0 / 6.0};
};

/// Butcher's explicit method of order 6 with 7 stages (J. C. Butcher, "On Runge-Kutta processes
/// of high order", J. Austral. Math. Soc. 4 (1964)).
struct ButcherRungeKutta6 {
  static constexpr int kStages = 7;
  static constexpr std::array<double, kStages> c = {0.0,       1.0 / 3.0, 2.0 / 3.0, 1.0 / 3.0,
                                                    1.0 / 2.0, 1.0 / 2.0, 1.0};
  static constexpr std::array<std::array<double, kStages>, kStages> a = {{
      {0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0},
      {1.0 / 3.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0},
      {0.0, 2.0 / 3.0, 0.0, 0.0, 0.0, 0.0, 0.0},
      {1.0 / 12.0, 1.0 / 3.0, -1.0 / 12.0, 0.0, 0.0, 0.0, 0.0},
      {-1.0 / 16.0, 9.0 / 8.0, -3.0 / 16.0, -3.0 / 8.0, 0.0, 0.0, 0.0},
      {0.0, 9.0 / 8.0, -3.0 / 8.0, -3.0 / 4.0, 1.0 / 2.0, 0.0, 0.0},
      {9.0 / 44.0, -9.0 / 11.0, 63.0 / 44.0, 18.0 / 11.0, 0.0, -16.0 / 11.0, 0.0},
  }};
  static constexpr std::array<double, kStages> b = {
      11.0 / 120.0, 0.0, 27.0 / 40.0, 27.0 / 40.0, -4.0 / 15.0, -4.0 / 15.0, 11.0 / 120.0};
};

template <typename Dims, typename Method>
class ContinuousRun {
 public:
  using StateVector = typename Dims::StateVector;
  using InputVector = typename Dims::InputVector;
  using State = ContinuousLoopState<Dims>;
  using Signals = ContinuousLoopSignals<Dims>;

  ContinuousRun(const Scenario& scenario, const ControllerDesign& design)
      : scenario_(scenario),
        design_(design),
        loop_(design),
        inputs_(design.parameters.model.inputDimension()),
        states_(design.parameters.model.stateDimension()),
        positions_(design.parameters.model.position_dimension),
        radius_(design.xi_max * (1.0 - 16.0 * std::numeric_limits<double>::epsilon())) {}

  /// u_1 at time t with the pulses taken at @p pulse_time.
  InputVector leaderInput(double t, double pulse_time) const {
    InputVector u1 = InputVector::Zero(inputs_);
    scenario_.leader_input.addPulsesTo(pulse_time, u1);
    scenario_.leader_input.addSinusoidsTo(t, u1);
    return u1;
  }

  /// u_d at time t with the pulses taken at @p pulse_time.
  StateVector disturbance(double t, double pulse_time) const {
    StateVector ud = StateVector::Zero(states_);
    scenario_.disturbance.addPulsesTo(pulse_time, ud);
    scenario_.disturbance.addSinusoidsTo(t, ud);
    return ud;
  }

  /// The pulse parts of u_1 and u_d, taken at @p pulse_time.
  void setPulses(double pulse_time) {
    leader_pulses_ = InputVector::Zero(inputs_);
    scenario_.leader_input.addPulsesTo(pulse_time, leader_pulses_);
    disturbance_pulses_ = StateVector::Zero(states_);
    scenario_.disturbance.addPulsesTo(pulse_time, disturbance_pulses_);
  }

  /// One step of the method of z from a to b with the pulses of setPulses() and the sinusoids of
  /// u_1 and u_d at the stage times a + c_i (b - a).
  void advance(double a, double b, State* z) const {
    const double h = b - a;
    const bool leader_varies = scenario_.leader_input.hasSinusoids();
    const bool disturbance_varies = scenario_.disturbance.hasSinusoids();
    InputVector u1 = leader_pulses_;
    StateVector ud = disturbance_pulses_;
    std::array<State, Method::kStages> k;
    State stage;
    for (int i = 0; i < Method::kStages; ++i) {
      stage = *z;
      for (int j = 0; j < i; ++j) {
        const double weight = h * Method::a[i][j];
        if (weight != 0.0) {
          stage.leader += weight * k[j].leader;
          stage.follower += weight * k[j].follower;
          stage.estimate += weight * k[j].estimate;
        }
      }
      const double t = a + Method::c[i] * h;
      if (leader_varies) {
        u1 = leader_pulses_;
        scenario_.leader_input.addSinusoidsTo(t, u1);
      }
      if (disturbance_varies) {
        ud = disturbance_pulses_;
        scenario_.disturbance.addSinusoidsTo(t, ud);
      }
      loop_.evaluate(stage, u1, ud, &k[i]);
    }
    // z += h sum_i b_i k_i, the sum formed first so that z is rounded once per step.
    State increment;
    increment.leader = Method::b[0] * k[0].leader;
    increment.follower = Method::b[0] * k[0].follower;
    increment.estimate = Method::b[0] * k[0].estimate;
    for (int i = 1; i < Method::kStages; ++i) {
      if (Method::b[i] != 0.0) {
        increment.leader += Method::b[i] * k[i].leader;
        increment.follower += Method::b[i] * k[i].follower;
        increment.estimate += Method::b[i] * k[i].estimate;
      }
    }
    z->leader += h * increment.leader;
    z->follower += h * increment.follower;
    z->estimate += h * increment.estimate;
  }

  SimulationSummary run(double step, const SampleObserver& observer) {
    const ControllerParameters& p = scenario_.controller;
    const FormationMember member =
        layoutFormation(scenario_.formation, p.separation, scenario_.leader_initial_state,
                        scenario_.follower_initial_state)
            .front();
    State z;
    z.leader = toBounded<StateVector>(scenario_.leader_initial_state);
    z.follower = toBounded<StateVector>(member.initial_state);
    z.estimate = StateVector::Zero(states_);
    if (p.initial_estimate == InitialEstimate::kMeasurement) {
      const StateVector xi0 = z.leader - z.follower - toBounded<StateVector>(member.separation);
      const typename Dims::ObserverGainMatrix output_pseudoinverse = design_.output_pseudoinverse;
      const typename Dims::OutputMatrix output_matrix = p.model.C;
      z.estimate = output_pseudoinverse * (output_matrix * xi0);
      clampNorm(z.estimate, radius_);
    }

    SimulationSummary summary;
    summary.xi_max = loop_.constraint().hardRadius();
    summary.perimeter = design_.perimeter;
    summary.min_separation = std::numeric_limits<double>::infinity();
    const long last_tick = std::lround(scenario_.duration / step);
    const double tolerance = 1e-9 * step;
    // Every pulse edge of u_1 and u_d, once; between two edges the pulses are constant.
    std::vector<double> edges = scenario_.leader_input.edgesWithin(
        -std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity());
    const std::vector<double> more = scenario_.disturbance.edgesWithin(
        -std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity());
    edges.insert(edges.end(), more.begin(), more.end());
    std::sort(edges.begin(), edges.end());
    std::size_t next_edge = 0;                // the first edge later than the step's start
    std::size_t pulses_segment = kNoSegment;  // the segment whose pulses setPulses() holds
    for (long tick = 0; tick <= last_tick; ++tick) {
      const double t = static_cast<double>(tick) * step;
      record(t, z, step, observer, &summary);
      if (tick == last_tick) {
        break;
      }
      const double t_end = static_cast<double>(tick + 1) * step;
      while (next_edge < edges.size() && edges[next_edge] <= t + tolerance) {
        ++next_edge;
      }
      if (next_edge == edges.size() || edges[next_edge] >= t_end - tolerance) {
        if (pulses_segment != next_edge) {
          setPulses(0.5 * (t + t_end));
          pulses_segment = next_edge;
        }
        advance(t, t_end, &z);
      } else {  // split at the edges inside (t, t_end), the pulses taken in each piece
        double a = t;
        for (; next_edge < edges.size() && edges[next_edge] < t_end - tolerance; ++next_edge) {
          if (edges[next_edge] > a) {
            setPulses(0.5 * (a + edges[next_edge]));
            advance(a, edges[next_edge], &z);
            a = edges[next_edge];
          }
        }
        setPulses(0.5 * (a + t_end));
        pulses_segment = kNoSegment;
        advance(a, t_end, &z);
      }
      const double norm = clampNorm(z.estimate, radius_);
      if (norm > 0.0) {
        summary.max_boundary_correction = std::max(summary.max_boundary_correction, norm - radius_);
      }
    }
    return summary;
  }

 private:
  void record(double t, const State& z, double step, const SampleObserver& observer,
              SimulationSummary* summary) const {
    const StateVector xi = z.leader - z.follower - design_.parameters.separation;
    const double xi_norm = xi.norm();
    double squared = 0.0;  // ||p_1 - p_2||^2 over the position entries
    for (int i = 0; i < positions_; ++i) {
      squared += (z.leader(i) - z.follower(i)) * (z.leader(i) - z.follower(i));
    }
    const double separation = std::sqrt(squared);
    summary->max_xi = std::max(summary->max_xi, xi_norm);
    summary->max_xi_hat = std::max(summary->max_xi_hat, z.estimate.norm());
    summary->min_separation = std::min(summary->min_separation, separation);
    if (xi_norm > summary->xi_max) {
      summary->time_outside += step;
    }
    ++summary->ticks;
    if (!observer) {
      return;
    }
    const InputVector u1 = leaderInput(t, t);
    const StateVector ud = disturbance(t, t);
    State derivative;
    Signals signals;
    loop_.evaluate(z, u1, ud, &derivative, &signals);
    SimulationSample sample;
    sample.time = t;
    sample.relative_error = xi;
    sample.leader_state = z.leader;
    sample.follower_state = z.follower;
    sample.distance = separation;
    sample.controller.estimate = z.estimate;
    sample.controller.estimate_norm = z.estimate.norm();
    sample.controller.constraint_value = signals.constraint_value;
    sample.controller.projection_active = signals.projection_active;
    sample.controller.command = signals.command;
    sample.controller.baseline_command = signals.baseline;
    sample.controller.tracker_command = signals.tracker;
    sample.leader_input = u1;
    sample.disturbance = ud;
    observer(sample);
  }

  const Scenario& scenario_;
  const ControllerDesign& design_;
  ContinuousDynamics<Dims> loop_;
  InputVector leader_pulses_;       // pulse part of u_1 over the current segment
  StateVector disturbance_pulses_;  // pulse part of u_d over the current segment
  Eigen::Index inputs_;
  Eigen::Index states_;
  int positions_;
  double radius_;
};

}  // namespace

SimulationSummary simulateContinuous(const Scenario& scenario, double step,
                                     const SampleObserver& observer, ContinuousMethod method) {
  const ControllerDesign design = ControllerDesign::create(scenario.controller);
  scenario.validate();
  if (scenario.formation.followers != 1) {
    throw ParameterError("formation.followers",
                         "the continuous-time loop runs the pair (one follower)");
  }
  if (scenario.formation.slots != SlotFrame::kWorld) {
    throw ParameterError("formation.slots",
                         "the continuous-time loop has world slots only (the sampled loop turns "
                         "them)");
  }
  if (scenario.link.active()) {
    const LinkSpec& link = scenario.link;
    throw ParameterError(std::string("controller.leader_information.link.") +
                             (link.delay_periods != 0 ? "delay_periods"
                              : link.latency != 0.0   ? "latency"
                                                      : "dropout"),
                         "a link is modelled by the sampled loop only (no --continuous)");
  }
  if (!(std::isfinite(step) && step > 0.0 && step <= scenario.duration)) {
    throw ParameterError("step", "must be finite, > 0 and at most simulation.duration");
  }
  const double steps = scenario.duration / step;
  if (std::abs(steps - std::round(steps)) > 1e-9 * std::max(1.0, steps)) {
    throw ParameterError("step", "must divide simulation.duration into a whole number of steps");
  }
  return visitDimensions(scenario.controller.model, [&](auto dims) {
    if (method == ContinuousMethod::kRungeKutta6) {
      ContinuousRun<decltype(dims), ButcherRungeKutta6> run(scenario, design);
      return run.run(step, observer);
    }
    ContinuousRun<decltype(dims), ClassicalRungeKutta4> run(scenario, design);
    return run.run(step, observer);
  });
}

}  // namespace projection_collision_avoidance
