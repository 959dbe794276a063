#include "projection_collision_avoidance/sim/SampledSimulator.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <locale>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "projection_collision_avoidance/core/ControllerDesign.hpp"
#include "projection_collision_avoidance/core/ConvoyReference.hpp"
#include "projection_collision_avoidance/core/DimensionDispatch.hpp"
#include "projection_collision_avoidance/core/FollowerController.hpp"
#include "projection_collision_avoidance/core/NeighbourBarrier.hpp"
#include "projection_collision_avoidance/core/PaperLaws.hpp"
#include "projection_collision_avoidance/core/ParameterError.hpp"
#include "projection_collision_avoidance/core/SafetyFilter.hpp"
#include "projection_collision_avoidance/core/TurningSlot.hpp"
#include "projection_collision_avoidance/sim/AgentIntegrator.hpp"
#include "projection_collision_avoidance/sim/SharedLink.hpp"
#include "projection_collision_avoidance/sim/VehicleResponse.hpp"

#include "SimulatedFollower.hpp"

namespace projection_collision_avoidance {
namespace {

using sim_detail::senseBarriers;
using sim_detail::senseNeighbours;
using sim_detail::SimulatedFollower;

/// ||p_a - p_b||^2 over the first k (position) entries.
template <typename Vector>
double squaredPositionDistance(const Vector& a, const Vector& b, int k) {
  double squared = 0.0;
  for (int i = 0; i < k; ++i) {
    const double delta = a(i) - b(i);
    squared += delta * delta;
  }
  return squared;
}

/// ||p_a - p_b|| over the first k (position) entries.
template <typename Vector>
double positionDistance(const Vector& a, const Vector& b, int k) {
  return std::sqrt(squaredPositionDistance(a, b, k));
}

/// The smallest squared distance of every pair of agents (0 the leader, i follower i) and which
/// pairs are neighbours (neither looks at the other).
class PairMinima {
 public:
  explicit PairMinima(const std::vector<FormationMember>& members)
      : agents_(members.size() + 1),
        minima_(agents_ * (agents_ - 1) / 2, std::numeric_limits<double>::infinity()),
        linked_(minima_.size(), false) {
    for (const FormationMember& member : members) {
      linked_[index(static_cast<std::size_t>(member.target),
                    static_cast<std::size_t>(member.index))] = true;
    }
  }

  /// The squared distance of agents a < b at a tick.
  void observe(std::size_t a, std::size_t b, double squared) {
    double& minimum = minima_[index(a, b)];
    minimum = std::min(minimum, squared);
  }

  /// min_neighbour_separation and the pairs that came closer than @p perimeter (m).
  void summarise(double perimeter, FormationSummary* summary) const {
    double neighbours = std::numeric_limits<double>::infinity();
    for (std::size_t p = 0; p < minima_.size(); ++p) {
      const bool inside = minima_[p] < perimeter * perimeter;
      summary->pairs_inside_perimeter += inside ? 1 : 0;
      if (!linked_[p]) {
        neighbours = std::min(neighbours, minima_[p]);
        summary->neighbour_pairs_inside_perimeter += inside ? 1 : 0;
      }
    }
    summary->perimeter = perimeter;
    summary->min_neighbour_separation = std::sqrt(neighbours);
  }

 private:
  /// Pair (a, b), a < b, in row order.
  std::size_t index(std::size_t a, std::size_t b) const {
    return a * agents_ - a * (a + 1) / 2 + (b - a - 1);
  }

  std::size_t agents_;
  std::vector<double> minima_;
  std::vector<bool> linked_;
};

template <typename Dims>
FormationSummary runFormation(const Scenario& scenario, const ControllerDesign& scenario_design,
                              const FormationObserver& observer) {
  using StateVector = typename Dims::StateVector;
  using InputVector = typename Dims::InputVector;
  using OutputVector = typename Dims::OutputVector;
  const ControllerParameters& p = scenario_design.parameters;
  const AgentModel& model = p.model;
  const Eigen::Index m = model.inputDimension();
  const Eigen::Index n = model.stateDimension();
  const int k = model.position_dimension;
  const bool share_leader_input = p.leader_input_in_command || p.leader_input_in_estimator;
  const typename Dims::OutputMatrix output_matrix = model.C;

  const bool turning = scenario.formation.slots == SlotFrame::kTurning;
  const bool path = scenario.formation.slots == SlotFrame::kPath;
  const std::vector<FormationMember> members =
      layoutFormation(scenario.formation, p.separation, scenario.leader_initial_state,
                      scenario.follower_initial_state);
  const int n_agents = static_cast<int>(members.size()) + 1;
  std::vector<SimulatedFollower<Dims>> followers;
  followers.reserve(members.size());
  const double neighbour_perimeter = std::isnan(scenario.formation.neighbours.perimeter)
                                         ? scenario_design.perimeter
                                         : scenario.formation.neighbours.perimeter;
  for (const FormationMember& member : members) {
    const Eigen::VectorXd& target_initial_state =
        member.target == 0 ? scenario.leader_initial_state
                           : members[static_cast<std::size_t>(member.target - 1)].initial_state;
    followers.emplace_back(
        member, ControllerDesign::create(memberParameters(p, member)), model,
        turning ? &scenario.formation.turning : nullptr, path ? &scenario.formation.path : nullptr,
        target_initial_state, scenario.world, scenario.duration,
        scenario.formation.neighbours.enabled ? &scenario.formation.neighbours : nullptr,
        neighbour_perimeter);
  }
  AgentIntegrator<Dims> leader(model, scenario_design.period, scenario.leader_initial_state,
                               scenario.disturbance);
  const StateVector zero_disturbance = StateVector::Zero(n);
  const bool need_disturbance = p.leader_disturbance_shared || static_cast<bool>(observer);
  const typename Dims::StateGainMatrix input_pseudoinverse = scenario_design.input_pseudoinverse;
  // The link of the shared accelerations (L1)-(L3): agent 0 the leader, i follower i. Without a
  // link section a follower gets its target's acceleration of the same tick.
  const bool use_link = share_leader_input && scenario.link.configured;
  SharedLink<InputVector> link(scenario.link, p.control_rate, use_link ? n_agents : 0,
                               use_link ? n_agents : 0, InputVector::Zero(m));

  const bool noisy = scenario.world.configured &&
                     (scenario.world.noise_position > 0.0 || scenario.world.noise_velocity > 0.0);
  FormationSummary formation;
  double min_pair_squared = std::numeric_limits<double>::infinity();
  // Per pair (a < b, agents 0 .. N), the smallest squared distance; and whether a looks at b.
  PairMinima pairs(members);
  const long last_tick = std::lround(scenario.duration * p.control_rate);
  for (long tick = 0; tick <= last_tick; ++tick) {
    const double t = static_cast<double>(tick) / p.control_rate;
    InputVector leader_input = InputVector::Zero(m);
    scenario.leader_input.addTo(t, leader_input);
    StateVector disturbance = zero_disturbance;
    if (need_disturbance) {
      scenario.disturbance.addTo(t, disturbance);
    }
    const InputVector leader_acceleration = sharedLeaderAcceleration(  // a_1
        p.leader_disturbance_shared, leader_input, input_pseudoinverse, disturbance);
    if (use_link) {
      link.send(0, tick, leader_acceleration);
    }
    for (SimulatedFollower<Dims>& follower : followers) {
      const bool behind_leader = follower.member.target == 0;
      const SimulatedFollower<Dims>* ahead =
          behind_leader ? nullptr
                        : &followers[static_cast<std::size_t>(follower.member.target - 1)];
      const StateVector& target_state = behind_leader ? leader.state() : ahead->plant.state();
      const InputVector& target_acceleration =
          use_link ? link.receive(follower.member.index, follower.member.target, tick)
                   : (behind_leader ? leader_acceleration : ahead->command);
      StateVector slot = follower.separation;  // D_i (T2)
      SlotHeadingSample heading;
      InputVector slot_acceleration;  // u_r (T3)
      if (follower.heading) {
        // The heading of the target's velocity: for C = I the follower's own velocity plus the
        // measured relative one.
        heading = follower.heading->tick(velocityHeading(target_state(k), target_state(k + 1),
                                                         scenario.formation.turning.min_speed));
        turningSlotOffset(follower.separation, k, heading, &slot);
        turningSlotAcceleration(follower.separation, k, heading, &slot_acceleration);
      }
      ConvoySample convoy;
      if (follower.convoy) {
        Eigen::Vector3d position = Eigen::Vector3d::Zero();
        Eigen::Vector3d velocity = Eigen::Vector3d::Zero();
        position.head(k) = target_state.head(k);
        velocity.head(k) = target_state.segment(k, k);
        convoy = follower.convoy->tick(position, velocity);
        convoySlotOffset(target_state, k, convoy, &slot);       // D_i (C4)
        convoySlotAcceleration(convoy, k, &slot_acceleration);  // u_r (C4)
      }
      const StateVector xi = target_state - follower.plant.state() - slot;
      StateVector measured = xi;  // xi with the world's measurement noise
      if (noisy) {
        for (Eigen::Index e = 0; e < n; ++e) {
          measured(e) += measurementNoise(scenario.world, follower.member.index, tick,
                                          static_cast<int>(e), static_cast<int>(n), k);
        }
      }
      const OutputVector y = output_matrix * measured;
      const StateVector& own_state = follower.plant.state();
      StepInputs<Dims> inputs{y, std::nullopt, own_state};
      if (share_leader_input) {
        inputs.leader_input = target_acceleration;
      }
      if (follower.heading || follower.convoy) {
        inputs.slot_acceleration = slot_acceleration;
      }
      if (follower.constraints) {
        senseNeighbours(follower, leader.state(), followers, k);
        inputs.command_constraints = &follower.constraints->projection();
      }
      if (follower.barriers) {
        Eigen::Vector3d a = Eigen::Vector3d::Zero();
        a.head(k) = target_acceleration.head(k);
        senseBarriers(follower, leader.state(), followers, a, share_leader_input,
                      scenario.formation.neighbours.neighbour_acceleration, k);
        inputs.safety_filter = &*follower.barriers;
      }
      const auto& status = follower.controller.step(inputs);
      follower.command = status.command;
      follower.summary.barrier_ticks += status.command_projected && follower.barriers ? 1 : 0;
      follower.summary.barrier_infeasible_ticks += status.barrier_infeasible ? 1 : 0;
      if (use_link) {
        link.send(follower.member.index, tick, follower.command);
      }

      SimulationSummary& summary = follower.summary;
      const double xi_norm = xi.norm();
      const double separation = positionDistance(target_state, follower.plant.state(), k);
      summary.max_xi = std::max(summary.max_xi, xi_norm);
      summary.max_xi_hat = std::max(summary.max_xi_hat, status.estimate_norm);
      summary.min_separation = std::min(summary.min_separation, separation);
      summary.max_boundary_correction =
          std::max(summary.max_boundary_correction, status.boundary_correction);
      if (xi_norm > follower.design.xi_max) {
        summary.time_outside += follower.design.period;
      }
      ++summary.ticks;

      if (observer) {
        SimulationSample sample;
        sample.time = t;
        sample.relative_error = xi;
        sample.leader_state = target_state;
        sample.follower_state = follower.plant.state();
        sample.distance = separation;
        sample.slot_heading = heading;
        sample.slot = slot;
        sample.convoy = convoy;
        sample.controller = status;
        sample.leader_input = behind_leader ? leader_input : ahead->command;
        sample.disturbance = behind_leader ? disturbance : zero_disturbance;
        observer(follower.member.index - 1, sample);
      }
    }
    // Squared distances, one square root at the end: sqrt is monotonic and correctly rounded,
    // so the minimum is the same double.
    for (std::size_t a = 0; a < followers.size(); ++a) {
      const StateVector& x_a = followers[a].plant.state();
      const double to_leader = squaredPositionDistance(x_a, leader.state(), k);
      min_pair_squared = std::min(min_pair_squared, to_leader);
      pairs.observe(0, a + 1, to_leader);
      for (std::size_t b = a + 1; b < followers.size(); ++b) {
        const double squared = squaredPositionDistance(x_a, followers[b].plant.state(), k);
        min_pair_squared = std::min(min_pair_squared, squared);
        pairs.observe(a + 1, b + 1, squared);
      }
    }
    if (tick < last_tick) {
      leader.advance(t, leader_input);
      for (SimulatedFollower<Dims>& follower : followers) {
        follower.plant.advance(
            t, follower.vehicle ? follower.vehicle->apply(follower.command) : follower.command);
      }
    }
  }
  formation.min_pair_separation = std::sqrt(min_pair_squared);
  pairs.summarise(scenario_design.perimeter, &formation);
  for (const SimulatedFollower<Dims>& follower : followers) {
    formation.followers.push_back(follower.summary);
    formation.targets.push_back(follower.member.target);
  }
  return formation;
}

}  // namespace

FormationSummary simulateFormation(const Scenario& scenario, const FormationObserver& observer) {
  const ControllerDesign design = ControllerDesign::create(scenario.controller);
  scenario.validate();
  return visitDimensions(scenario.controller.model, [&](auto dims) {
    return runFormation<decltype(dims)>(scenario, design, observer);
  });
}

SimulationSummary simulate(const Scenario& scenario, const SampleObserver& observer) {
  if (scenario.formation.followers != 1) {
    throw ParameterError("formation.followers",
                         "simulate() runs one follower; use simulateFormation()");
  }
  FormationObserver forward;
  if (observer) {
    forward = [&observer](int /*member*/, const SimulationSample& sample) { observer(sample); };
  }
  return simulateFormation(scenario, forward).followers.front();
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
  if (summary.barrier_filter) {
    line << " barrier_ticks=" << summary.barrier_ticks
         << " barrier_infeasible_ticks=" << summary.barrier_infeasible_ticks;
  }
  return line.str();
}

}  // namespace projection_collision_avoidance
