/// The control barrier function filter (controller.safety_filter, doc/math.md (B1)-(B3)) in
/// cf_sim's sampled loop: its keys, the paper's Run 2 with it, a formation with it.

#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "projection_collision_avoidance/core/ParameterError.hpp"
#include "projection_collision_avoidance/scenario/CfSimApp.hpp"
#include "projection_collision_avoidance/scenario/ScenarioLoader.hpp"
#include "projection_collision_avoidance/sim/SampledSimulator.hpp"

#include "TestScenarios.hpp"

namespace projection_collision_avoidance {
namespace {

using testing::scenarioPath;

const std::string kFilter = "controller.safety_filter={rate: 2}";
const std::string kNoTracker = "controller.tracker.enabled=false";

std::string keyOfError(const std::vector<std::string>& overrides,
                       const std::string& file = "paper_run2.yaml") {
  try {
    loadScenarioFile(scenarioPath(file), overrides);
  } catch (const ParameterError& error) {
    return error.key();
  }
  return "";
}

TEST(BarrierFilterKeys, AreReadAndRefusedNamingTheKey) {
  const Scenario scenario =
      loadScenarioFile(scenarioPath("paper_run2.yaml"), {kNoTracker, kFilter});
  ASSERT_TRUE(scenario.controller.safety_filter.has_value());
  EXPECT_DOUBLE_EQ(scenario.controller.safety_filter->rate, 2.0);
  EXPECT_FALSE(loadScenarioFile(scenarioPath("paper_run2.yaml")).controller.safety_filter);
  // The default rate.
  EXPECT_DOUBLE_EQ(
      loadScenarioFile(scenarioPath("paper_run2.yaml"), {kNoTracker, "controller.safety_filter={}"})
          .controller.safety_filter->rate,
      SafetyFilterParameters{}.rate);

  const std::string rate = "controller.safety_filter.rate";
  for (const char* bad : {"0", "-1", ".nan", ".inf", "\"fast\""}) {
    EXPECT_EQ(keyOfError({kNoTracker, rate + "=" + bad}), rate) << bad;
  }
  EXPECT_EQ(keyOfError({kNoTracker, "controller.safety_filter={gain: 1}"}),
            "controller.safety_filter.gain");
  EXPECT_EQ(keyOfError({kNoTracker, "controller.safety_filter=3"}), "controller.safety_filter");
  // The nominal command is the baseline law's: the CF tracker cannot run with it.
  EXPECT_EQ(keyOfError({kFilter}), "controller.tracker.enabled");
  // The barrier (B1) is on positions of double integrators.
  EXPECT_EQ(keyOfError({"model={type: linear, A: [[0, 1], [0, -1]], B: [[0], [1]], "
                        "position_dimension: 1}",
                        "controller.baseline={gain: [[1.0, 1.4]]}", kNoTracker, kFilter}),
            "controller.safety_filter");
}

TEST(BarrierFilterKeys, TheContinuousLoopRefusesIt) {
  std::ostringstream out;
  std::ostringstream err;
  const int code = runCfSim({scenarioPath("paper_run2.yaml"), "--set", kNoTracker, "--set", kFilter,
                             "--continuous", "0.01"},
                            out, err);
  EXPECT_EQ(code, 2);
  EXPECT_NE(err.str().find("controller.safety_filter"), std::string::npos) << err.str();
}

// Run 2 with its push a velocity rate of 8 m/s^2 (the leader's acceleration, shared with the
// follower: a_j of (B2) known): the baseline law alone comes inside the perimeter; the filter on
// the same baseline keeps it out, as (B2)'s guarantee says, moving the command only around the
// push.
const std::vector<std::string> kVelocityPush = {
    kNoTracker, "leader.disturbance=[{start: 20.0, end: 23.0, vector: [0.0, -8.0]}]",
    "controller.leader_information={estimator: true, disturbance: true}"};

std::vector<std::string> with(std::vector<std::string> overrides, const std::string& more) {
  overrides.push_back(more);
  return overrides;
}

TEST(BarrierFilterRuns, AKnownAccelerationPushKeepsThePerimeterWhereTheBaselineDoesNot) {
  const SimulationSummary baseline =
      simulate(loadScenarioFile(scenarioPath("paper_run2.yaml"), kVelocityPush));
  const SimulationSummary filtered =
      simulate(loadScenarioFile(scenarioPath("paper_run2.yaml"), with(kVelocityPush, kFilter)));
  EXPECT_FALSE(baseline.barrier_filter);
  EXPECT_EQ(baseline.barrier_ticks, 0);
  EXPECT_LT(baseline.min_separation, baseline.perimeter);
  ASSERT_TRUE(filtered.barrier_filter);
  EXPECT_GE(filtered.min_separation, filtered.perimeter);
  EXPECT_GT(filtered.barrier_ticks, 0);
  EXPECT_LT(filtered.barrier_ticks, filtered.ticks / 4);  // near the push, not over the run
  EXPECT_EQ(filtered.barrier_infeasible_ticks, 0);        // no acceleration limit: always feasible
}

// The paper's own push is mostly a position rate (u_d = [-2 m/s, -2 m/s^2]), which the relative
// state (p, v) the barrier is written on does not carry: v = v_i - v_j is not the rate of p then,
// and the filter, believing the agents part, lets them meet as the baseline does.
TEST(BarrierFilterRuns, APositionRatePushIsNotSeenByTheBarrierOnTheState) {
  const SimulationSummary filtered =
      simulate(loadScenarioFile(scenarioPath("paper_run2.yaml"), {kNoTracker, kFilter}));
  EXPECT_LT(filtered.min_separation, filtered.perimeter);
  EXPECT_GT(filtered.max_xi, filtered.xi_max);
}

// With an acceleration limit the barrier cannot always be met: the ticks are counted.
TEST(BarrierFilterRuns, ALimitTooSmallForThePushIsCountedAsInfeasible) {
  const SimulationSummary filtered =
      simulate(loadScenarioFile(scenarioPath("paper_run2.yaml"),
                                with(with(kVelocityPush, "controller.safety_filter={rate: 5}"),
                                     "controller.acceleration_limit=10")));
  EXPECT_GT(filtered.barrier_infeasible_ticks, 0);
  EXPECT_LE(filtered.barrier_infeasible_ticks, filtered.barrier_ticks);
}

// Without the section every run is as before: the summary line carries no barrier figures.
TEST(BarrierFilterRuns, TheSummaryLineNamesTheFilterOnlyWithIt) {
  const SimulationSummary plain = simulate(loadScenarioFile(scenarioPath("paper_run2.yaml")));
  EXPECT_EQ(formatSummary(plain, 0.0).find("barrier"), std::string::npos);
  const SimulationSummary filtered =
      simulate(loadScenarioFile(scenarioPath("paper_run2.yaml"), {kNoTracker, kFilter}));
  EXPECT_NE(formatSummary(filtered, 0.0).find(" barrier_ticks="), std::string::npos);
}

}  // namespace
}  // namespace projection_collision_avoidance
