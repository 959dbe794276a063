/// Google Benchmark of one control step of the follower (1-D, 2-D and 3-D double integrators,
/// with the estimate inside the bound and held on it by the projection) and of whole cf_sim runs
/// of the paper's scenario. Not a test: experiments/performance/run.sh runs it.
///
/// Counters: substeps (RK4 substeps per period), allocations (heap allocations per step, counted
/// by test/common/AllocationCounter.cpp), flops (StepFlops.hpp) and flops_per_ns.

#include <cmath>

#include <benchmark/benchmark.h>

#include "projection_collision_avoidance/core/ControllerDesign.hpp"
#include "projection_collision_avoidance/core/FollowerController.hpp"
#include "projection_collision_avoidance/scenario/ScenarioLoader.hpp"
#include "projection_collision_avoidance/sim/ContinuousSimulator.hpp"
#include "projection_collision_avoidance/sim/SampledSimulator.hpp"
#include "projection_collision_avoidance/sim/ScenarioEmbedding.hpp"

#include "AllocationCounter.hpp"
#include "StepFlops.hpp"

namespace projection_collision_avoidance {
namespace {

std::string scenarioPath(const char* name) { return std::string(SCENARIO_DIR) + "/" + name; }

/// The paper's Run 2 in k axes, along the diagonal so that every axis is used.
Scenario paperScenario(int axes) {
  const Scenario one_axis = loadScenarioFile(scenarioPath("paper_run2.yaml"));
  return axes == 1 ? one_axis : embedAlongDirection(one_axis, Eigen::VectorXd::Ones(axes));
}

/// One step on a constant measurement: 0.5 m on every axis (inside the 4 m bound: no
/// projection) or 6 m (outside: after the warm-up the estimate sits on the bound and the
/// projection acts at every derivative evaluation).
template <typename Dims>
void followerStep(benchmark::State& state, bool outside) {
  constexpr int kAxes = Dims::kInputs;
  const ControllerDesign design = ControllerDesign::create(paperScenario(kAxes).controller);
  FollowerController<Dims> controller(design);
  typename Dims::OutputVector y = Dims::OutputVector::Zero();
  y.template head<kAxes>().setConstant((outside ? 6.0 : 0.5) / std::sqrt(double(kAxes)));
  for (int k = 0; k < 1000; ++k) {  // warm-up: the estimate converges (onto the bound)
    controller.step({y});
  }
  if (controller.status().projection_active != outside) {
    state.SkipWithError("the projection is not in the intended regime");
    return;
  }
  const long allocations_before = testing::allocationCount();
  for (auto _ : state) {
    benchmark::DoNotOptimize(controller.step({y}).command);
  }
  const double steps = static_cast<double>(state.iterations());
  const long substeps = design.parameters.estimator_substeps;
  const double flops = static_cast<double>(
      benchmarking::stepFlops(Dims::kStates, Dims::kInputs, Dims::kOutputs, substeps, outside));
  state.counters["substeps"] = static_cast<double>(substeps);
  state.counters["allocations"] =
      static_cast<double>(testing::allocationCount() - allocations_before) / steps;
  state.counters["flops"] = flops;
  state.counters["flops_per_ns"] =
      benchmark::Counter(flops * steps * 1e-9, benchmark::Counter::kIsRate);
}

template <typename Dims>
void BM_FollowerStep(benchmark::State& state) {
  followerStep<Dims>(state, false);
}
template <typename Dims>
void BM_FollowerStepProjected(benchmark::State& state) {
  followerStep<Dims>(state, true);
}
BENCHMARK_TEMPLATE(BM_FollowerStep, DoubleIntegrator1D);
BENCHMARK_TEMPLATE(BM_FollowerStep, DoubleIntegrator2D);
BENCHMARK_TEMPLATE(BM_FollowerStep, DoubleIntegrator3D);
BENCHMARK_TEMPLATE(BM_FollowerStepProjected, DoubleIntegrator1D);
BENCHMARK_TEMPLATE(BM_FollowerStepProjected, DoubleIntegrator2D);
BENCHMARK_TEMPLATE(BM_FollowerStepProjected, DoubleIntegrator3D);

/// The paper's Run 2 (60 s), sampled controller at the scenario's 1 kHz, in process.
void BM_PaperRun2Sampled(benchmark::State& state) {
  const Scenario scenario = paperScenario(1);
  for (auto _ : state) {
    benchmark::DoNotOptimize(simulate(scenario).max_xi);
  }
  state.counters["ticks"] =
      static_cast<double>(std::lround(scenario.duration * scenario.controller.control_rate)) + 1;
}
BENCHMARK(BM_PaperRun2Sampled)->Unit(benchmark::kMillisecond);

/// The paper's Run 2 (60 s) in continuous time, RK4 at 5 ms, in process.
void BM_PaperRun2Continuous(benchmark::State& state) {
  const Scenario scenario = paperScenario(1);
  for (auto _ : state) {
    benchmark::DoNotOptimize(simulateContinuous(scenario, 0.005).max_xi);
  }
}
BENCHMARK(BM_PaperRun2Continuous)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace projection_collision_avoidance

BENCHMARK_MAIN();
