/// Google Benchmark of one control step of the follower (1-D, 2-D and 3-D double integrators)
/// and of a whole cf_sim run of the paper's scenario. Not a test: run it by hand, see README.

#include <cmath>

#include <benchmark/benchmark.h>

#include "projection_collision_avoidance/ClosedLoopSimulator.hpp"
#include "projection_collision_avoidance/ControllerDesign.hpp"
#include "projection_collision_avoidance/FollowerController.hpp"
#include "projection_collision_avoidance/ScenarioEmbedding.hpp"
#include "projection_collision_avoidance/ScenarioLoader.hpp"

namespace projection_collision_avoidance {
namespace {

std::string scenarioPath(const char* name) { return std::string(SCENARIO_DIR) + "/" + name; }

/// The paper's Run 2 in k axes, along the diagonal so that every axis is used.
Scenario paperScenario(int axes) {
  const Scenario one_axis = loadScenarioFile(scenarioPath("paper_run2.yaml"));
  return axes == 1 ? one_axis : embedAlongDirection(one_axis, Eigen::VectorXd::Ones(axes));
}

template <typename Dims>
void BM_FollowerStep(benchmark::State& state) {
  constexpr int kAxes = Dims::kInputs;
  const Scenario scenario = paperScenario(kAxes);
  const ControllerDesign design = ControllerDesign::create(scenario.controller);
  FollowerController<Dims> controller(design);
  typename Dims::OutputVector y = Dims::OutputVector::Constant(1.0);
  // Alternate between a measurement inside the bound and one far outside, so that both the
  // plain and the projected drift are timed.
  int k = 0;
  for (auto _ : state) {
    y(0) = (k++ & 1) ? 0.5 : 6.0;
    benchmark::DoNotOptimize(controller.step(y).command);
  }
  state.counters["substeps"] = design.parameters.estimator_substeps;
}
BENCHMARK_TEMPLATE(BM_FollowerStep, DoubleIntegrator1D);
BENCHMARK_TEMPLATE(BM_FollowerStep, DoubleIntegrator2D);
BENCHMARK_TEMPLATE(BM_FollowerStep, DoubleIntegrator3D);

void BM_PaperRun2(benchmark::State& state) {
  const Scenario scenario = paperScenario(1);
  for (auto _ : state) {
    benchmark::DoNotOptimize(simulate(scenario).max_xi);
  }
  state.counters["ticks"] =
      static_cast<double>(std::lround(scenario.duration * scenario.controller.control_rate)) + 1;
}
BENCHMARK(BM_PaperRun2)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace projection_collision_avoidance

BENCHMARK_MAIN();
