/// Google Benchmark of one follower step of each method of doc/comparison.md, as cf_sim makes
/// it: the baseline law alone, the paper's CF estimator and tracker, and the barrier filter
/// ((B1)-(B3): the target's barrier built from the relative state, then the filter), in 1-D, 2-D
/// and 3-D, with the barrier slack (the target at its slot) and binding (2-D and 3-D: the target
/// 1.2 m to the side, where the baseline law would close in). Not a test:
/// experiments/comparison/cpu.sh runs it.
///
/// Counters: allocations (heap allocations per step, test/common/AllocationCounter.cpp),
/// filtered (1 when the filter moved the command at the last step).

#include <cmath>
#include <string>

#include <benchmark/benchmark.h>

#include "projection_collision_avoidance/core/ControllerDesign.hpp"
#include "projection_collision_avoidance/core/FollowerController.hpp"
#include "projection_collision_avoidance/core/SafetyFilter.hpp"
#include "projection_collision_avoidance/scenario/ScenarioLoader.hpp"
#include "projection_collision_avoidance/sim/ScenarioEmbedding.hpp"

#include "AllocationCounter.hpp"

namespace projection_collision_avoidance {
namespace {

enum class Method { kBaseline, kCf, kBarrier };

/// The paper's Run 2 design in k axes (d along the first axis), for @p method.
ControllerDesign designFor(int axes, Method method) {
  const Scenario one_axis = loadScenarioFile(std::string(SCENARIO_DIR) + "/paper_run2.yaml");
  Eigen::VectorXd direction = Eigen::VectorXd::Zero(axes);
  direction(0) = 1.0;
  ControllerParameters p =
      axes == 1 ? one_axis.controller : embedAlongDirection(one_axis, direction).controller;
  p.tracker_enabled = method == Method::kCf;
  if (method == Method::kBarrier) {
    p.safety_filter = SafetyFilterParameters{};
  }
  return ControllerDesign::create(p);
}

template <typename Dims>
void methodStep(benchmark::State& state, Method method, bool binding) {
  constexpr int kAxes = Dims::kInputs;
  const ControllerDesign design = designFor(kAxes, method);
  FollowerController<Dims> controller(design);
  SafetyFilter filter(kAxes);
  // The relative state x_target - x_i: at the slot d, or 1.2 m to the side (binding).
  typename Dims::StateVector relative = Dims::StateVector::Zero();
  if (binding) {
    relative(1) = 1.2;
  } else {
    relative(0) = design.parameters.separation(0);
  }
  const typename Dims::OutputVector y = relative - design.parameters.separation;
  const double rate = method == Method::kBarrier ? design.parameters.safety_filter->rate : 0.0;
  auto step = [&]() -> const FollowerControllerStatus<Dims>& {
    StepInputs<Dims> inputs{y};
    if (method == Method::kBarrier) {
      Eigen::Vector3d p = Eigen::Vector3d::Zero();
      Eigen::Vector3d v = Eigen::Vector3d::Zero();
      p.head(kAxes) = -relative.template head<kAxes>();
      v.head(kAxes) = -relative.template tail<kAxes>();
      filter.clear();
      filter.add(exponentialBarrier(p, v, Eigen::Vector3d::Zero(), design.perimeter, rate));
      inputs.safety_filter = &filter;
    }
    return controller.step(inputs);
  };
  for (int k = 0; k < 1000; ++k) {
    step();
  }
  const bool filtered = controller.status().command_projected;
  if (method == Method::kBarrier && filtered != binding) {
    state.SkipWithError("the barrier is not in the intended regime");
    return;
  }
  const long allocations_before = testing::allocationCount();
  for (auto _ : state) {
    benchmark::DoNotOptimize(step().command);
  }
  state.counters["allocations"] =
      static_cast<double>(testing::allocationCount() - allocations_before) /
      static_cast<double>(state.iterations());
  state.counters["filtered"] = filtered ? 1.0 : 0.0;
}

template <typename Dims>
void BM_Baseline(benchmark::State& state) {
  methodStep<Dims>(state, Method::kBaseline, false);
}
template <typename Dims>
void BM_CfTracker(benchmark::State& state) {
  methodStep<Dims>(state, Method::kCf, false);
}
template <typename Dims>
void BM_BarrierSlack(benchmark::State& state) {
  methodStep<Dims>(state, Method::kBarrier, false);
}
template <typename Dims>
void BM_BarrierBinding(benchmark::State& state) {
  methodStep<Dims>(state, Method::kBarrier, true);
}
BENCHMARK_TEMPLATE(BM_Baseline, DoubleIntegrator1D);
BENCHMARK_TEMPLATE(BM_Baseline, DoubleIntegrator2D);
BENCHMARK_TEMPLATE(BM_Baseline, DoubleIntegrator3D);
BENCHMARK_TEMPLATE(BM_CfTracker, DoubleIntegrator1D);
BENCHMARK_TEMPLATE(BM_CfTracker, DoubleIntegrator2D);
BENCHMARK_TEMPLATE(BM_CfTracker, DoubleIntegrator3D);
BENCHMARK_TEMPLATE(BM_BarrierSlack, DoubleIntegrator1D);
BENCHMARK_TEMPLATE(BM_BarrierSlack, DoubleIntegrator2D);
BENCHMARK_TEMPLATE(BM_BarrierSlack, DoubleIntegrator3D);
BENCHMARK_TEMPLATE(BM_BarrierBinding, DoubleIntegrator2D);
BENCHMARK_TEMPLATE(BM_BarrierBinding, DoubleIntegrator3D);

}  // namespace
}  // namespace projection_collision_avoidance

BENCHMARK_MAIN();
