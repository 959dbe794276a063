/// The paper's two simulation runs (Sec. IV, math note's scenario) on the offline simulator.

#include <gtest/gtest.h>

#include "projection_collision_avoidance/scenario/ScenarioLoader.hpp"
#include "projection_collision_avoidance/sim/SampledSimulator.hpp"
#include "projection_collision_avoidance/sim/ScenarioEmbedding.hpp"

#include "EigenTestHelpers.hpp"
#include "TestScenarios.hpp"

namespace projection_collision_avoidance {
namespace {

using testing::scenarioPath;

struct Trace {
  std::vector<SimulationSample> samples;
  SimulationSummary summary;
};

Trace run(const Scenario& scenario) {
  Trace trace;
  trace.summary =
      simulate(scenario, [&](const SimulationSample& s) { trace.samples.push_back(s); });
  return trace;
}

// Run 1, tracker off: xi leaves the bound (peak near 5.2 m, separation down to about 0.1 m)
// while the estimate never leaves it and follows xi whenever xi is inside.
TEST(PaperRuns, Run1LeavesTheBoundWhileTheEstimateStaysInside) {
  const Trace trace = run(loadScenarioFile(scenarioPath("paper_run1.yaml")));
  const SimulationSummary& s = trace.summary;
  EXPECT_GT(s.max_xi, s.xi_max);
  EXPECT_NEAR(s.max_xi, 5.2, 0.1);
  EXPECT_NEAR(s.min_separation, 0.1, 0.05);
  EXPECT_GT(s.time_outside, 1.0);
  EXPECT_LE(s.max_xi_hat, s.xi_max);
  EXPECT_GT(s.max_xi_hat, 0.999 * s.xi_max);  // the estimate saturates on the bound
  for (const SimulationSample& sample : trace.samples) {
    ASSERT_LE(sample.controller.estimate.norm(), s.xi_max) << "t=" << sample.time;
    // Before the disturbance and once xi has settled back, the estimate is xi.
    if (sample.time < 20.0 || sample.time > 40.0) {
      ASSERT_LT((sample.controller.estimate - sample.relative_error).norm(), 1e-3)
          << "t=" << sample.time;
    }
  }
  // The RK4 safeguard on the sphere removes next to nothing: the projection does the work.
  EXPECT_LT(s.max_boundary_correction, 1e-9);
}

// Run 2, tracker on: xi stays near 3 m at most and the separation near 3.9 m.
TEST(PaperRuns, Run2StaysInsideTheBound) {
  const Trace trace = run(loadScenarioFile(scenarioPath("paper_run2.yaml")));
  const SimulationSummary& s = trace.summary;
  EXPECT_LT(s.max_xi, s.xi_max);
  EXPECT_NEAR(s.max_xi, 3.0, 0.15);
  EXPECT_NEAR(s.min_separation, 3.9, 0.1);
  EXPECT_GT(s.min_separation, s.perimeter);
  EXPECT_EQ(s.time_outside, 0.0);
  EXPECT_LE(s.max_xi_hat, s.xi_max);
  // While u_d acts the estimator, blind to it, is biased; afterwards xi returns to xi_hat.
  for (const SimulationSample& sample : trace.samples) {
    if (sample.time > 45.0) {
      ASSERT_LT((sample.controller.estimate - sample.relative_error).norm(), 1e-3)
          << "t=" << sample.time;
    }
  }
}

// A sampled controller converges to the continuous-time figures: 100 Hz lands within a few
// centimetres of 1 kHz.
TEST(PaperRuns, SampledRunsAgreeAcrossControlRates) {
  for (const char* name : {"paper_run1.yaml", "paper_run2.yaml"}) {
    const SimulationSummary fast = simulate(loadScenarioFile(scenarioPath(name)));
    const SimulationSummary slow =
        simulate(loadScenarioFile(scenarioPath(name), {"controller.control_rate=100"}));
    EXPECT_NEAR(fast.max_xi, slow.max_xi, 0.05) << name;
    EXPECT_NEAR(fast.min_separation, slow.min_separation, 0.05) << name;
    const SimulationSummary substeps =
        simulate(loadScenarioFile(scenarioPath(name), {"controller.estimator.substeps=8"}));
    EXPECT_NEAR(fast.max_xi, substeps.max_xi, 1e-6) << name;
  }
}

// The same scenario rotated into 2-D and 3-D: identical norms and separations.
TEST(PaperRuns, RotatedIntoTwoAndThreeDimensionsGivesTheSameNorms) {
  for (const char* name : {"paper_run1.yaml", "paper_run2.yaml"}) {
    const Scenario one_axis = loadScenarioFile(scenarioPath(name));
    const Trace reference = run(one_axis);
    for (const Eigen::VectorXd& direction : {Eigen::VectorXd(Eigen::Vector2d(0.6, -0.8)),
                                             Eigen::VectorXd(Eigen::Vector3d(1.0, 2.0, -2.0)),
                                             Eigen::VectorXd(Eigen::Vector3d(0.0, 0.0, 1.0))}) {
      const Trace rotated = run(embedAlongDirection(one_axis, direction));
      ASSERT_EQ(rotated.samples.size(), reference.samples.size());
      EXPECT_NEAR(rotated.summary.max_xi, reference.summary.max_xi, 1e-9);
      EXPECT_NEAR(rotated.summary.max_xi_hat, reference.summary.max_xi_hat, 1e-9);
      EXPECT_NEAR(rotated.summary.min_separation, reference.summary.min_separation, 1e-9);
      EXPECT_NEAR(rotated.summary.time_outside, reference.summary.time_outside, 1e-9);
      for (std::size_t k = 0; k < reference.samples.size(); k += 97) {
        const SimulationSample& a = reference.samples[k];
        const SimulationSample& b = rotated.samples[k];
        ASSERT_NEAR(a.relative_error.norm(), b.relative_error.norm(), 1e-9) << "t=" << a.time;
        ASSERT_NEAR(a.controller.estimate.norm(), b.controller.estimate.norm(), 1e-9)
            << "t=" << a.time;
        ASSERT_NEAR(a.controller.command.norm(), b.controller.command.norm(), 1e-9)
            << "t=" << a.time;
      }
    }
  }
}

// With an acceleration limit the command never exceeds it, the status says when it acted, the
// estimate still respects its bound, and Run 2 stays safe with a limit the unsaturated run
// exceeds.
TEST(PaperRuns, AccelerationLimitBoundsTheCommand) {
  const Trace free_run = run(loadScenarioFile(scenarioPath("paper_run2.yaml")));
  double largest = 0.0;
  for (const SimulationSample& sample : free_run.samples) {
    largest = std::max(largest, sample.controller.command.norm());
  }
  const double limit = 0.8 * largest;
  Scenario scenario = loadScenarioFile(scenarioPath("paper_run2.yaml"));
  scenario.controller.acceleration_limit = limit;
  const Trace limited = run(scenario);
  int saturated = 0;
  for (const SimulationSample& sample : limited.samples) {
    ASSERT_LE(sample.controller.command.norm(), limit * (1.0 + 1e-12)) << "t=" << sample.time;
    ASSERT_LE(sample.controller.estimate.norm(), limited.summary.xi_max);
    const Eigen::VectorXd sum =
        sample.controller.baseline_command + sample.controller.tracker_command;
    if (sum.norm() > limit) {
      ++saturated;
      EXPECT_NEAR(sample.controller.command.norm(), limit, 1e-9);
      EXPECT_NEAR(sample.controller.command.normalized().dot(sum.normalized()), 1.0,
                  1e-12);  // direction
    } else {
      ASSERT_NEAR((sample.controller.command - sum).norm(), 0.0, 1e-12);
    }
  }
  EXPECT_GT(saturated, 0);
  EXPECT_LT(limited.summary.max_xi, limited.summary.xi_max);
  EXPECT_GT(limited.summary.min_separation, limited.summary.perimeter);
}

// A 2-D run through the generic (run-time sized) controller matches the fixed-size one.
TEST(PaperRuns, GenericDimensionsMatchFixedDimensions) {
  const Scenario one_axis = loadScenarioFile(scenarioPath("paper_run2.yaml"));
  Scenario planar = embedAlongDirection(one_axis, Eigen::Vector2d(1.0, 1.0));
  const SimulationSummary fixed = simulate(planar);
  // Same model written as a "linear" one with C = I padded by a zero row: p = 5, so the generic
  // controller runs.
  planar.controller.model.C = Eigen::MatrixXd::Zero(5, 4);
  planar.controller.model.C.topRows(4).setIdentity();
  planar.controller.model.double_integrator_axes = 0;
  auto pad = [](const Eigen::MatrixXd& M) {
    Eigen::MatrixXd padded = Eigen::MatrixXd::Zero(M.rows(), 5);
    padded.leftCols(4) = M;
    return padded;
  };
  planar.controller.baseline_gain = pad(planar.controller.baseline_gain);
  planar.controller.estimator_gain = pad(planar.controller.estimator_gain);
  planar.controller.tracker_gain = pad(planar.controller.tracker_gain);
  planar.controller.reference_gain = pad(planar.controller.reference_gain);
  const SimulationSummary generic = simulate(planar);
  EXPECT_NEAR(generic.max_xi, fixed.max_xi, 1e-9);
  EXPECT_NEAR(generic.max_xi_hat, fixed.max_xi_hat, 1e-9);
  EXPECT_NEAR(generic.min_separation, fixed.min_separation, 1e-9);
}

}  // namespace
}  // namespace projection_collision_avoidance
