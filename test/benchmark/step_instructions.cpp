/// Runs STEPS control steps of the follower, as benchmark_follower_step does, for an instruction
/// count under callgrind (experiments/performance/run.sh runs it at two step counts and divides the
/// difference, so that start-up cancels out).
/// Usage: step_instructions AXES(1|2|3) STEPS inside|outside

#include <cmath>
#include <cstdio>
#include <string>

#include "projection_collision_avoidance/core/ControllerDesign.hpp"
#include "projection_collision_avoidance/core/FollowerController.hpp"
#include "projection_collision_avoidance/scenario/ScenarioLoader.hpp"
#include "projection_collision_avoidance/sim/ScenarioEmbedding.hpp"

namespace projection_collision_avoidance {
namespace {

template <typename Dims>
double run(long steps, bool outside) {
  constexpr int kAxes = Dims::kInputs;
  Scenario scenario = loadScenarioFile(std::string(SCENARIO_DIR) + "/paper_run2.yaml");
  if (kAxes > 1) {
    scenario = embedAlongDirection(scenario, Eigen::VectorXd::Ones(kAxes));
  }
  FollowerController<Dims> controller(ControllerDesign::create(scenario.controller));
  typename Dims::OutputVector y = Dims::OutputVector::Zero();
  y.template head<kAxes>().setConstant((outside ? 6.0 : 0.5) / std::sqrt(double(kAxes)));
  double sum = 0.0;
  for (int k = 0; k < 1000; ++k) {  // the same warm-up as the benchmark
    sum += controller.step({y}).command(0);
  }
  for (long k = 0; k < steps; ++k) {
    sum += controller.step({y}).command(0);
  }
  return sum;
}

}  // namespace
}  // namespace projection_collision_avoidance

int main(int argc, char** argv) {
  using namespace projection_collision_avoidance;  // NOLINT(google-build-using-namespace)
  if (argc != 4) {
    std::fprintf(stderr, "usage: step_instructions AXES(1|2|3) STEPS inside|outside\n");
    return 2;
  }
  // NOLINTBEGIN(cppcoreguidelines-pro-bounds-pointer-arithmetic)
  const int axes = std::stoi(argv[1]);
  const long steps = std::stol(argv[2]);
  const bool outside = std::string(argv[3]) == "outside";
  // NOLINTEND(cppcoreguidelines-pro-bounds-pointer-arithmetic)
  double sum = 0.0;
  if (axes == 1) {
    sum = run<DoubleIntegrator1D>(steps, outside);
  } else if (axes == 2) {
    sum = run<DoubleIntegrator2D>(steps, outside);
  } else if (axes == 3) {
    sum = run<DoubleIntegrator3D>(steps, outside);
  } else {
    std::fprintf(stderr, "step_instructions: AXES must be 1, 2 or 3\n");
    return 2;
  }
  std::printf("%.17g\n", sum);
  return 0;
}
