/// The disturbance sweep: its scenarios, its search, and the figures it must reproduce.

#include <cmath>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "projection_collision_avoidance/core/ParameterError.hpp"
#include "projection_collision_avoidance/scenario/ScenarioLoader.hpp"
#include "projection_collision_avoidance/sim/DisturbanceSweep.hpp"
#include "projection_collision_avoidance/sim/SampledSimulator.hpp"

#include "EigenTestHelpers.hpp"
#include "TestScenarios.hpp"

namespace projection_collision_avoidance {
namespace {

using testing::scenarioPath;

constexpr double kPi = 3.141592653589793;

Scenario base() {
  return loadScenarioFile(scenarioPath("paper_run2.yaml"), {"controller.control_rate=100"});
}

TEST(SweepScenario, PutsTheSizeAndDirectionIntoThePulse) {
  const Scenario paper =
      sweepScenario(base(), {true, LeaderSharing::kNone}, 1.25 * kPi, 2.0 * std::sqrt(2.0));
  ASSERT_EQ(paper.disturbance.pulses.size(), 1u);
  EXPECT_MATRIX_NEAR(paper.disturbance.pulses[0].vector, Eigen::Vector2d(-2.0, -2.0), 1e-12);
  EXPECT_DOUBLE_EQ(paper.disturbance.pulses[0].start, 20.0);
  EXPECT_DOUBLE_EQ(paper.disturbance.pulses[0].end, 23.0);
  // The paper's Run 2 is the point (tracker on, no sharing, 225 deg, 2 sqrt 2).
  EXPECT_NEAR(simulate(paper).max_xi, simulate(base()).max_xi, 1e-12);

  const Scenario shared = sweepScenario(base(), {false, LeaderSharing::kBoth}, 0.0, 1.0);
  EXPECT_FALSE(shared.controller.tracker_enabled);
  EXPECT_TRUE(shared.controller.leader_input_in_command);
  EXPECT_TRUE(shared.controller.leader_input_in_estimator);
  EXPECT_TRUE(shared.controller.leader_disturbance_shared);
  const Scenario estimator = sweepScenario(base(), {true, LeaderSharing::kEstimator}, 0.0, 1.0);
  EXPECT_FALSE(estimator.controller.leader_input_in_command);
  EXPECT_TRUE(estimator.controller.leader_input_in_estimator);
}

TEST(SweepScenario, RefusesWhatItCannotSweep) {
  const auto keyOf = [](const Scenario& scenario) -> std::string {
    try {
      sweepScenario(scenario, {}, 0.0, 1.0);
    } catch (const ParameterError& error) {
      return error.key();
    }
    return "";
  };
  Scenario two_pulses = base();
  two_pulses.disturbance.pulses.push_back(two_pulses.disturbance.pulses[0]);
  EXPECT_EQ(keyOf(two_pulses), "leader.disturbance");
  Scenario formation = base();
  formation.formation.followers = 2;
  EXPECT_EQ(keyOf(formation), "formation.followers");
  SweepOptions options;
  options.directions = 0;
  EXPECT_THROW(options.validate(), ParameterError);
  options = SweepOptions{};
  options.tolerance = 1.0;  // wider than the step
  EXPECT_THROW(options.validate(), ParameterError);
}

/// A coarse sweep: 0, 90, 180, 270 deg, sizes up to 8 in steps of 1, on 40 s of Run 2.
SweepOptions coarseOptions() {
  SweepOptions options;
  options.directions = 4;
  options.max_size = 8.0;
  options.size_step = 1.0;
  options.tolerance = 0.01;
  return options;
}

Scenario shortRun() {
  Scenario scenario = base();
  scenario.duration = 40.0;
  return scenario;
}

TEST(DisturbanceSweep, FindsTheLimitsAtTheEdgeOfSafety) {
  const SweepOptions options = coarseOptions();
  const Scenario short_run = shortRun();
  const std::vector<SweepPoint> points = sweepDisturbance(short_run, options);
  ASSERT_EQ(points.size(), sweepConfigurations().size() * 4);
  for (const SweepPoint& point : points) {
    SCOPED_TRACE(std::string("tracker ") + (point.configuration.tracker ? "on" : "off") + ", " +
                 toString(point.configuration.sharing) + ", " +
                 std::to_string(point.direction * 180.0 / kPi) + " deg");
    for (const bool bound : {true, false}) {
      const double limit = bound ? point.bound_limit : point.perimeter_limit;
      const bool capped = bound ? point.bound_capped : point.perimeter_capped;
      ASSERT_GE(limit, 0.0);
      ASSERT_LE(limit, options.max_size);
      // Just inside the limit the run is safe, just outside it is not (unless capped).
      const auto held = [&](double size) {
        const SimulationSummary s =
            simulate(sweepScenario(short_run, point.configuration, point.direction, size));
        return bound ? s.max_xi <= s.xi_max : s.min_separation >= s.perimeter;
      };
      if (limit > 0.0) {
        EXPECT_TRUE(held(limit));
      }
      if (capped) {
        EXPECT_DOUBLE_EQ(limit, options.max_size);
      } else {
        EXPECT_FALSE(held(limit + options.tolerance));
      }
    }
  }
}

TEST(DisturbanceSweep, SharingHelpsAgainstAccelerationsAndNotAgainstPositionRates) {
  const std::vector<SweepPoint> points = sweepDisturbance(shortRun(), coarseOptions());
  const auto find = [&](bool tracker, LeaderSharing sharing, int direction) {
    for (const SweepPoint& p : points) {
      if (p.configuration.tracker == tracker && p.configuration.sharing == sharing &&
          std::lround(p.direction * 2.0 / kPi) == direction) {
        return p;
      }
    }
    ADD_FAILURE() << "point missing";
    return SweepPoint{};
  };
  for (const bool tracker : {false, true}) {
    // 270 deg: an acceleration toward the follower. Fed forward, it is cancelled at any size.
    EXPECT_TRUE(find(tracker, LeaderSharing::kCommand, 3).perimeter_capped);
    EXPECT_TRUE(find(tracker, LeaderSharing::kCommand, 3).bound_capped);
    // 180 deg: a position rate toward the follower. No sharing mode changes anything.
    for (const LeaderSharing sharing :
         {LeaderSharing::kCommand, LeaderSharing::kEstimator, LeaderSharing::kBoth}) {
      EXPECT_EQ(find(tracker, sharing, 2).perimeter_limit,
                find(tracker, LeaderSharing::kNone, 2).perimeter_limit);
      EXPECT_EQ(find(tracker, sharing, 2).bound_limit,
                find(tracker, LeaderSharing::kNone, 2).bound_limit);
    }
  }
  // Without the tracker and without sharing, the same acceleration breaks the perimeter.
  EXPECT_FALSE(find(false, LeaderSharing::kNone, 3).perimeter_capped);
  // The tracker widens the bound's limit against the position rate (the paper's claim).
  EXPECT_GT(find(true, LeaderSharing::kNone, 2).bound_limit,
            find(false, LeaderSharing::kNone, 2).bound_limit);
}

}  // namespace
}  // namespace projection_collision_avoidance
