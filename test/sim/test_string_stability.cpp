/// String stability of chains (doc/math.md, "Platoons"): the time headway (S1) and its CF
/// estimator, the shaped feed-forward (S2), the figures of StringStability.hpp, the default
/// chain's growth, and the string-stable configuration at N = 100 over a link with delay and
/// losses at 100 Hz and 1 kHz (no roscore).

#include <cmath>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <gtest/gtest.h>

#include "projection_collision_avoidance/core/ControllerDesign.hpp"
#include "projection_collision_avoidance/core/PlatoonLaws.hpp"
#include "projection_collision_avoidance/scenario/ScenarioLoader.hpp"
#include "projection_collision_avoidance/sim/SampledSimulator.hpp"
#include "projection_collision_avoidance/sim/StringStability.hpp"

#include "TestScenarios.hpp"

namespace projection_collision_avoidance {
namespace {

using testing::scenarioPath;

TEST(FeedforwardFilter, IsTheFirstOrderLowPassOfS2) {
  const double a = std::exp(-0.01 / 0.2);
  FeedforwardFilter<Eigen::Matrix<double, 1, 1>> filter(0.7, a, 1);
  EXPECT_TRUE(filter.shapes());
  const Eigen::Matrix<double, 1, 1> one = Eigen::Matrix<double, 1, 1>::Ones();
  for (int k = 0; k < 300; ++k) {  // a step: u_ff(k) = kappa (1 - a^(k+1))
    EXPECT_NEAR(filter.apply(one)(0), 0.7 * (1.0 - std::pow(a, k + 1)), 1e-14) << k;
  }
  filter.reset();
  EXPECT_NEAR(filter.apply(one)(0), 0.7 * (1.0 - a), 1e-15);
  FeedforwardFilter<Eigen::Matrix<double, 1, 1>> none(1.0, 0.0, 1);
  EXPECT_FALSE(none.shapes());
  EXPECT_EQ(none.apply(0.3 * one)(0), 0.3);
}

TEST(TimeHeadway, GainMovesTheSlotBackAlongTheVelocity) {
  ControllerParameters p = testing::paperParameters();
  p.time_headway = 0.3;
  // 1-D: K_h = -G M = -[k_p, k_v] [[0, h], [0, 0]] = [0, -k_p h].
  EXPECT_TRUE(timeHeadwayGain(p).isApprox(Eigen::RowVector2d(0.0, -0.3), 1e-15));
  // 2-D: the slot moves back by h v whatever the direction of v; positions play no part.
  ControllerParameters q = p;
  q.model = makeDoubleIntegrator(2);
  q.separation = Eigen::Vector4d(3.0, 4.0, 0.0, 0.0);
  q.baseline_gain = doubleIntegratorGain(Eigen::Vector2d(1.0, 2.0), Eigen::Vector2d(0.7, 0.7), "g");
  const Eigen::MatrixXd K = timeHeadwayGain(q);
  for (const Eigen::Vector2d& v : {Eigen::Vector2d(-0.8, 0.6), Eigen::Vector2d(1.2, 1.6)}) {
    const Eigen::Vector4d state(7.0, -2.0, v(0), v(1));
    const Eigen::Vector2d expected = -q.baseline_gain.leftCols(2) * (0.3 * v);
    EXPECT_TRUE((K * state).isApprox(expected, 1e-14)) << v.transpose();
  }
  p.time_headway = 0.0;
  EXPECT_EQ(timeHeadwayGain(p).norm(), 0.0);
}

/// The pair with the leader cruising at @p speed (m/s), from xi = 0, with the headway h.
std::vector<SimulationSample> cruise(double speed, double headway, double duration) {
  const std::string v = std::to_string(speed);
  const Scenario scenario = loadScenarioFile(
      scenarioPath("paper_run2.yaml"),
      {"controller.control_rate=100", "leader.disturbance=[]",
       "leader.initial_state=[5.0, " + v + "]", "follower.initial_state=[0.0, " + v + "]",
       "controller.spacing.time_headway=" + std::to_string(headway),
       "simulation.duration=" + std::to_string(duration)});
  std::vector<SimulationSample> samples;
  simulate(scenario, [&samples](const SimulationSample& s) { samples.push_back(s); });
  return samples;
}

TEST(TimeHeadway, TheGapGrowsWithSpeedAndTheEstimatorFollows) {
  // At 2 m/s with h = 0.5 s the follower settles h v = 1 m further back: xi_p = 1, xi_v = 0.
  // The headway is a known input to the CF estimator, so the estimate follows xi and the
  // tracker stays idle.
  const std::vector<SimulationSample> run = cruise(2.0, 0.5, 40.0);
  const SimulationSample& last = run.back();
  EXPECT_NEAR(last.relative_error(0), 1.0, 1e-4);
  EXPECT_NEAR(last.relative_error(1), 0.0, 1e-4);
  EXPECT_NEAR((last.controller.estimate - last.relative_error).norm(), 0.0, 1e-4);
  EXPECT_NEAR(last.controller.tracker_command.norm(), 0.0, 1e-3);
  EXPECT_NEAR(last.distance, 6.0, 1e-4);
  // Reversing at 2 m/s the slot comes 1 m closer; the bound is still on xi.
  EXPECT_NEAR(cruise(-2.0, 0.5, 40.0).back().relative_error(0), -1.0, 1e-4);
}

TEST(TimeHeadway, TheEstimateStaysInOmega1WhenTheHeadwayAsksForMore) {
  // h |v| = 0.6 x 10 = 6 m > xi_max = 4 m: the projection holds the estimate in Omega_1 (the
  // invariance does not depend on the drift), and the tracker pulls xi toward it.
  const std::vector<SimulationSample> run = cruise(10.0, 0.6, 40.0);
  bool projected = false;
  for (const SimulationSample& s : run) {
    ASSERT_LE(s.controller.estimate.norm(), 4.0 + 1e-9) << s.time;
    projected = projected || s.controller.projection_active;
  }
  EXPECT_TRUE(projected);
  EXPECT_LT(run.back().relative_error.norm(), 6.0 - 1.0);  // the tracker won most of it back
}

FormationSummary platoon(const std::vector<std::string>& overrides) {
  return simulateFormation(loadScenarioFile(scenarioPath("platoon_run2.yaml"), overrides));
}

/// Every follower keeps its bound and stays out of its perimeter, and no peak exceeds the peak
/// of the agent ahead.
void expectStringStableAndSafe(const FormationSummary& run, std::size_t followers) {
  ASSERT_EQ(run.followers.size(), followers);
  for (std::size_t i = 0; i < followers; ++i) {
    const SimulationSummary& f = run.followers[i];
    EXPECT_LE(f.max_xi, f.xi_max) << "follower " << i + 1;
    EXPECT_LE(f.max_xi_hat, f.xi_max) << "follower " << i + 1;
    EXPECT_GE(f.min_separation, f.perimeter) << "follower " << i + 1;
    if (i > 0) {
      EXPECT_LE(f.max_xi, run.followers[i - 1].max_xi) << "follower " << i + 1;
    }
  }
  EXPECT_GE(run.min_pair_separation, run.followers.front().perimeter);
  const StringStabilityFigures figures = stringStabilityFigures(run);
  EXPECT_EQ(figures.first_outside_bound, 0);
  EXPECT_EQ(figures.first_inside_perimeter, 0);
  EXPECT_LE(figures.peak_ratio_max, 1.0);
  EXPECT_LE(figures.peak_growth, 1.0);
}

TEST(StringStability, ChosenConfigurationHoldsAChainOf100At100Hz) {
  // 100 ms as whole periods, 20 % losses, a seed the report does not use.
  const FormationSummary run =
      platoon({"controller.leader_information.link={delay_periods: 10, "
               "dropout: 0.2, seed: 2024}"});
  expectStringStableAndSafe(run, 100);
  // The push is felt: the first follower's peak is far from zero.
  EXPECT_GT(run.followers.front().max_xi, 1.0);
}

TEST(StringStability, ChosenConfigurationHoldsAChainOf100At1kHz) {
  const FormationSummary run = platoon({"controller.control_rate=1000",
                                        "controller.leader_information.link={latency: "
                                        "0.1, dropout: 0.2, seed: 77}"});
  expectStringStableAndSafe(run, 100);
}

TEST(StringStability, ChosenConfigurationAttenuatesTheWaveWhenTheLeaderStops) {
  // After the push the leader brakes to rest: no steady reverse speed, so no steady headway
  // offset h |v| either, and every peak is the transient's. It must shrink along the chain.
  const FormationSummary run =
      platoon({"leader.input={pulses: [{start: 23.0, end: 29.0, vector: [1.0]}]}",
               "controller.leader_information.link={latency: 0.15, dropout: 0.2, seed: 5}"});
  expectStringStableAndSafe(run, 100);
  const StringStabilityFigures figures = stringStabilityFigures(run);
  EXPECT_LT(figures.peak_ratio_max, 1.0 - 1e-3);
  EXPECT_LT(figures.peak_growth, 0.995);
  EXPECT_LT(run.followers.back().max_xi, 0.5 * run.followers.front().max_xi);
}

TEST(StringStability, TheDelayedFeedForwardAloneIsNotEnough) {
  // Without the headway and the shaping, the raw feed-forward 100 ms late lets the error grow
  // along the chain: the figures must say so.
  const FormationSummary run =
      platoon({"formation.followers=30", "controller.spacing.time_headway=0",
               "controller.leader_information.feedforward={gain: 1.0, time_constant: 0.0}"});
  const StringStabilityFigures figures = stringStabilityFigures(run);
  EXPECT_GT(figures.peak_ratio_max, 1.1);
  EXPECT_GT(figures.peak_growth, 1.1);
  EXPECT_GT(figures.first_outside_bound, 0);
}

TEST(StringStability, TheDefaultChainIsDetectedUnstable) {
  // The paper's laws in a chain, nothing shared, tracker on (issue 15): the peak grows about
  // 15 % per follower, followers leave their bound and then enter their perimeter.
  const FormationSummary run = simulateFormation(loadScenarioFile(
      scenarioPath("paper_run2.yaml"),
      {"controller.control_rate=100", "formation.followers=30", "formation.topology=chain"}));
  const StringStabilityFigures figures = stringStabilityFigures(run);
  EXPECT_GT(figures.peak_growth, 1.1);
  EXPECT_GT(figures.peak_ratio_max, 1.1);
  ASSERT_GT(figures.first_outside_bound, 1);
  EXPECT_GT(run.followers[figures.first_outside_bound - 1].max_xi,
            run.followers[figures.first_outside_bound - 1].xi_max);
  EXPECT_LE(run.followers[figures.first_outside_bound - 2].max_xi,
            run.followers[figures.first_outside_bound - 2].xi_max);
  ASSERT_GT(figures.first_inside_perimeter, figures.first_outside_bound);
  EXPECT_LT(run.followers[figures.first_inside_perimeter - 1].min_separation,
            run.followers[figures.first_inside_perimeter - 1].perimeter);
  // A star of the same laws: every follower sees the pair's run, nothing grows.
  const FormationSummary star = simulateFormation(loadScenarioFile(
      scenarioPath("paper_run2.yaml"),
      {"controller.control_rate=100", "formation.followers=30", "formation.topology=star"}));
  const StringStabilityFigures star_figures = stringStabilityFigures(star);
  EXPECT_TRUE(std::isnan(star_figures.peak_ratio_max));  // no follower looks at a follower
  EXPECT_EQ(star_figures.first_outside_bound, 0);
  for (const SimulationSummary& f : star.followers) {
    EXPECT_NEAR(f.max_xi, star.followers.front().max_xi, 1e-9);
  }
}

TEST(StringStability, FiguresOfHandMadeSummaries) {
  FormationSummary summary;
  for (const double peak : {3.0, 2.0, 2.5, 5.0}) {
    SimulationSummary f;
    f.max_xi = peak;
    f.xi_max = 4.0;
    f.perimeter = 1.0;
    f.min_separation = 5.0 - peak;
    summary.followers.push_back(f);
  }
  const StringStabilityFigures figures = stringStabilityFigures(summary);
  EXPECT_EQ(figures.first_outside_bound, 4);
  EXPECT_EQ(figures.first_inside_perimeter, 4);  // 0 < 1
  EXPECT_DOUBLE_EQ(figures.peak_ratio_max, 2.0);
  EXPECT_NEAR(figures.peak_growth, std::sqrt(2.5), 1e-15);  // (5 / 2)^(1 / 2)
  // A V chain: followers 1 and 2 see the leader, 3 looks at 1 and 4 at 2.
  summary.targets = {0, 0, 1, 2};
  const StringStabilityFigures v = stringStabilityFigures(summary);
  EXPECT_DOUBLE_EQ(v.peak_ratio_max, 2.5);  // 5 / 2
  EXPECT_TRUE(std::isnan(v.peak_growth));   // nobody behind a follower's follower
  summary.targets = {0, 0, 0, 0};           // a star: nothing is passed on
  EXPECT_TRUE(std::isnan(stringStabilityFigures(summary).peak_ratio_max));
  summary.targets.clear();
  summary.followers[2].max_xi = 1e-12;  // rounding noise: no ratio
  EXPECT_TRUE(std::isnan(stringStabilityFigures(summary).peak_ratio_max));
  summary.followers.resize(1);
  EXPECT_TRUE(std::isnan(stringStabilityFigures(summary).peak_growth));
}

}  // namespace
}  // namespace projection_collision_avoidance
