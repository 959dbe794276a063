/// Google Benchmark of the follower's step with neighbour protection (doc/math.md, "Neighbours",
/// (N1)-(N3)) against the number of sensed agents, in 2-D and 3-D. Each step does what cf_sim
/// does per follower and tick: NeighbourConstraints::clear(), add() per sensed agent,
/// projection(), then FollowerController::step() with StepInputs::command_constraints. Not a
/// test: experiments/neighbours/cpu.sh runs it and writes the CPU table of doc/formations.md.
///
/// Benchmarks are named neighbours_<k>d/<case>/max_<max_neighbours>/agents_<N>, N = 1, 2, 4, 8,
/// 16, 32, 64 (a follower of a formation of F senses the F - 1 others and the leader: F agents):
///   none  N = 0, no constraints given (the step without protection);
///   far   the agents at rest on a ring (3-D: a sphere) of 10 m: every one kept (up to
///         max_neighbours), none binding: the command is feasible and comes back unchanged;
///   arc   closing in at 1 m/s from ahead (within 60 degrees of +x), 3.5 to 6 m away: the
///         barriers bind the command;
///   ring  closing in at 1 m/s from every side, 3.5 to 6 m away: squeezed, the priority fallback
///         drops the half-spaces that cannot all be met.
/// A case whose last step is not in its regime (none or far projected, arc not projected, far
/// not keeping every agent it may) is reported as an error.
/// Counters per step: allocations (test/common/AllocationCounter.cpp; must be 0), and of the last
/// step sensed, kept (the half-spaces given), active, dropped, projected and the command's norm.

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include <benchmark/benchmark.h>

#include "projection_collision_avoidance/core/ControllerDesign.hpp"
#include "projection_collision_avoidance/core/FollowerController.hpp"
#include "projection_collision_avoidance/core/NeighbourBarrier.hpp"
#include "projection_collision_avoidance/scenario/ScenarioLoader.hpp"

#include "AllocationCounter.hpp"

namespace projection_collision_avoidance {
namespace {

/// Where the sensed agents are (see the file comment).
enum class Crowd { kNone, kFar, kArc, kRing };

const char* crowdName(Crowd crowd) {
  switch (crowd) {
    case Crowd::kNone:
      return "none";
    case Crowd::kFar:
      return "far";
    case Crowd::kArc:
      return "arc";
    case Crowd::kRing:
      return "ring";
  }
  return "?";
}

/// One sensed agent relative to the follower: p = p_i - p_j (m), v = v_i - v_j (m/s).
struct RelativeAgent {
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();
};

/// Direction e_j (unit, first @p axes entries) from the follower to agent j of @p count: spread
/// evenly over the circle (2-D) or the sphere (3-D, a Fibonacci lattice) for the far and ring
/// crowds, within 60 degrees of +x for the arc.
Eigen::Vector3d agentDirection(Crowd crowd, int axes, int j, int count) {
  constexpr double kPi = 3.14159265358979323846;
  const double fraction = (j + 0.5) / count;  // in (0, 1)
  const bool arc = crowd == Crowd::kArc;
  if (axes == 2) {
    const double angle = arc ? (kPi / 3.0) * (2.0 * fraction - 1.0) : 2.0 * kPi * fraction + 0.1;
    return {std::cos(angle), std::sin(angle), 0.0};
  }
  // 3-D: the component along +x evenly in [cos 60deg, 1] (a cap) or [-1, 1] (the sphere), the
  // azimuth about x by the golden angle.
  const double along = arc ? 1.0 - 0.5 * fraction : 1.0 - 2.0 * fraction;
  const double across = std::sqrt(std::max(0.0, 1.0 - along * along));
  const double azimuth = j * kPi * (3.0 - std::sqrt(5.0));
  return {along, across * std::cos(azimuth), across * std::sin(azimuth)};
}

/// The @p count agents of @p crowd around a follower at the origin.
std::vector<RelativeAgent> placeAgents(Crowd crowd, int axes, int count) {
  std::vector<RelativeAgent> agents(static_cast<std::size_t>(count));
  for (int j = 0; j < count; ++j) {
    const Eigen::Vector3d e = agentDirection(crowd, axes, j, count);
    RelativeAgent& agent = agents[static_cast<std::size_t>(j)];
    if (crowd == Crowd::kFar) {
      agent.position = -10.0 * e;  // at rest, 10 m away
      continue;
    }
    // 3.5 to 6 m, spread by the golden ratio; closing at 1 m/s: v_j = -e, so v_i - v_j = e.
    const double phase = std::fmod(j * 0.6180339887498949, 1.0);
    agent.position = -(3.5 + 2.5 * phase) * e;
    agent.velocity = e;
  }
  return agents;
}

/// The design of a gusty V's follower (crowd_16_gusts.yaml, a_max = 4 m/s^2), in k axes.
ControllerDesign crowdDesign(int axes) {
  const std::string dir = SCENARIO_DIR;
  const Scenario scenario = axes == 2 ? loadScenarioFile(dir + "/crowd_16_gusts.yaml")
                                      : loadScenarioFile(dir + "/figure_eight_3d.yaml",
                                                         {"controller.acceleration_limit=4.0"});
  return ControllerDesign::create(scenario.controller);
}

/// formation.neighbours as experiments/neighbours runs the gusty stars, with max_neighbours.
NeighbourParameters crowdProtection(int max_neighbours) {
  NeighbourParameters parameters;
  parameters.enabled = true;
  parameters.perimeter = 1.0;
  parameters.braking_acceleration = 1.5;
  parameters.neighbour_acceleration = 2.5;
  parameters.rate = 1.0;
  parameters.max_neighbours = max_neighbours;
  return parameters;
}

/// One follower step with @p count sensed agents of @p crowd, at most @p max_neighbours kept. The
/// follower lags its slot by 0.5 m along x and 0.25 m along y, at rest relative to it, and every
/// step starts from the estimate xi_hat = pinv(C) y: the paper's command, the same at every
/// step, pushes it ahead (toward +x) with 0.56 m/s^2, which the far agents' half-spaces
/// n^T u >= 2.5 - sqrt(27) = -2.70 m/s^2 leave as it is. (Without a plant a step carried over
/// from the last would not be steady: the estimate, integrated with the command while y stays,
/// drifts until the command saturates at a_max. resetEstimate(), a copy and a norm, is in every
/// case's step, none's too.)
template <typename Dims>
void neighbourStep(benchmark::State& state, Crowd crowd, int count, int max_neighbours) {
  constexpr int kAxes = Dims::kInputs;
  const ControllerDesign design = crowdDesign(kAxes);
  FollowerController<Dims> controller(design);
  NeighbourConstraints constraints(crowdProtection(max_neighbours), 1.0, kAxes,
                                   design.parameters.acceleration_limit);
  const std::vector<RelativeAgent> agents = placeAgents(crowd, kAxes, count);
  typename Dims::OutputVector y = Dims::OutputVector::Zero();
  y(0) = 0.5;
  y(1) = 0.25;
  const typename Dims::StateVector estimate = design.output_pseudoinverse * y;
  StepInputs<Dims> inputs{y};
  auto step = [&]() -> const FollowerControllerStatus<Dims>& {
    if (crowd != Crowd::kNone) {
      constraints.clear();
      for (const RelativeAgent& agent : agents) {
        constraints.add(agent.position, agent.velocity);
      }
      inputs.command_constraints = &constraints.projection();
    }
    controller.resetEstimate(estimate);
    return controller.step(inputs);
  };
  for (int k = 0; k < 1000; ++k) {  // warm-up (caches, branch predictors)
    step();
  }
  const long allocations_before = testing::allocationCount();
  for (auto _ : state) {
    benchmark::DoNotOptimize(step().command);
  }
  const long allocations = testing::allocationCount() - allocations_before;
  const FollowerControllerStatus<Dims>& last = controller.status();
  state.counters["allocations"] =
      static_cast<double>(allocations) / static_cast<double>(state.iterations());
  state.counters["sensed"] = crowd == Crowd::kNone ? 0.0 : constraints.sensed();
  state.counters["kept"] = last.constraints_given;
  state.counters["active"] = last.constraints_active;
  state.counters["dropped"] = last.constraints_dropped;
  state.counters["projected"] = last.command_projected ? 1.0 : 0.0;
  state.counters["command"] = last.command.norm();
  const bool far_kept = last.constraints_given == std::min(count, max_neighbours);
  if ((crowd == Crowd::kNone || crowd == Crowd::kFar) && last.command_projected) {
    state.SkipWithError("the command was projected: a barrier binds");
  } else if (crowd == Crowd::kFar && !far_kept) {
    state.SkipWithError("not every far agent was kept");
  } else if (crowd == Crowd::kArc && !last.command_projected) {
    state.SkipWithError("the arc's barriers do not bind");
  }
}

/// Registers every case of @p Dims: N = 0 once, then each crowd, max_neighbours 8 and 32 and N.
template <typename Dims>
void registerCases() {
  const std::string prefix = "neighbours_" + std::to_string(Dims::kInputs) + "d/";
  benchmark::RegisterBenchmark(
      (prefix + "none/max_0/agents_0").c_str(),
      [](benchmark::State& state) { neighbourStep<Dims>(state, Crowd::kNone, 0, 8); });
  for (const Crowd crowd : {Crowd::kFar, Crowd::kArc, Crowd::kRing}) {
    for (const int max_neighbours : {8, 32}) {
      for (const int count : {1, 2, 4, 8, 16, 32, 64}) {
        const std::string name = prefix + crowdName(crowd) + "/max_" +
                                 std::to_string(max_neighbours) + "/agents_" +
                                 std::to_string(count);
        benchmark::RegisterBenchmark(name.c_str(), [=](benchmark::State& state) {
          neighbourStep<Dims>(state, crowd, count, max_neighbours);
        });
      }
    }
  }
}

}  // namespace
}  // namespace projection_collision_avoidance

int main(int argc, char** argv) {
  using namespace projection_collision_avoidance;
  registerCases<DoubleIntegrator2D>();
  registerCases<DoubleIntegrator3D>();
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) {
    return 1;
  }
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
