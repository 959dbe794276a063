/// A world that can hurt (section `world`, WorldSpec): disturbances on followers, seeded gusts,
/// true vehicles apart from the model, measurement noise; the pairs' figures; the keys; and that
/// an empty world leaves the runs as they were, bit for bit (no roscore).

#include <cmath>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <gtest/gtest.h>

#include "projection_collision_avoidance/core/ParameterError.hpp"
#include "projection_collision_avoidance/scenario/ScenarioLoader.hpp"
#include "projection_collision_avoidance/sim/SampledSimulator.hpp"
#include "projection_collision_avoidance/sim/SharedLink.hpp"
#include "projection_collision_avoidance/sim/VehicleResponse.hpp"
#include "projection_collision_avoidance/sim/WorldSpec.hpp"

#include "TestScenarios.hpp"

namespace projection_collision_avoidance {
namespace {

using testing::scenarioPath;

FormationSummary run(const std::string& file, const std::vector<std::string>& overrides = {},
                     const FormationObserver& observer = {}) {
  return simulateFormation(loadScenarioFile(scenarioPath(file), overrides), observer);
}

std::string keyOfError(const std::vector<std::string>& overrides) {
  try {
    loadScenarioFile(scenarioPath("crowd_v4_gust.yaml"), overrides);
  } catch (const ParameterError& error) {
    return error.key();
  }
  return "";
}

void expectSameRun(const FormationSummary& a, const FormationSummary& b) {
  ASSERT_EQ(a.followers.size(), b.followers.size());
  for (std::size_t i = 0; i < a.followers.size(); ++i) {
    EXPECT_EQ(a.followers[i].max_xi, b.followers[i].max_xi) << "follower " << i + 1;
    EXPECT_EQ(a.followers[i].max_xi_hat, b.followers[i].max_xi_hat) << "follower " << i + 1;
    EXPECT_EQ(a.followers[i].min_separation, b.followers[i].min_separation);
  }
  EXPECT_EQ(a.min_pair_separation, b.min_pair_separation);
}

TEST(World, AnEmptyWorldChangesNothingBitForBit) {
  // The same file without its world, and with an empty one: the same doubles.
  const FormationSummary none = run("crowd_v4_gust.yaml", {"world=~"});
  expectSameRun(none, run("crowd_v4_gust.yaml", {"world={}"}));
  expectSameRun(none, run("crowd_v4_gust.yaml",
                          {"world={vehicle: {acceleration_limit: .inf, input_gain: 1}}"}));
  EXPECT_EQ(none.pairs_inside_perimeter, 0);
}

TEST(World, AFollowersDisturbanceMovesThatFollowerAlone) {
  // In a star no follower depends on another: the gust on follower 2 leaves 1, 3 and 4 as they
  // were, bit for bit, and takes 2 near 1.
  const FormationSummary calm = run("crowd_v4_gust.yaml", {"world.followers=[]"});
  const FormationSummary gust = run("crowd_v4_gust.yaml");
  for (const std::size_t i : {0U, 2U, 3U}) {
    EXPECT_EQ(calm.followers[i].max_xi, gust.followers[i].max_xi) << "follower " << i + 1;
  }
  EXPECT_GT(gust.followers[1].max_xi, 10.0 * calm.followers[1].max_xi);
  EXPECT_GE(calm.min_neighbour_separation, calm.perimeter);
  EXPECT_LT(gust.min_neighbour_separation, gust.perimeter);
  EXPECT_GE(gust.neighbour_pairs_inside_perimeter, 1);
}

TEST(World, PairFiguresAreTheMinimaOverEveryTick) {
  // Recomputed from the observer's states: every pair, and the neighbours (neither looks at the
  // other; in a star every pair of followers).
  std::vector<std::vector<Eigen::Vector2d>> positions;  // [tick][agent]
  const FormationSummary summary =
      run("crowd_v4_gust.yaml", {}, [&](int member, const SimulationSample& sample) {
        if (member == 0) {
          positions.push_back(std::vector<Eigen::Vector2d>(5, Eigen::Vector2d::Zero()));
          positions.back()[0] = sample.leader_state.head<2>();
        }
        positions.back()[static_cast<std::size_t>(member) + 1] = sample.follower_state.head<2>();
      });
  double all = INFINITY;
  double neighbours = INFINITY;
  for (const auto& tick : positions) {
    for (std::size_t a = 0; a < 5; ++a) {
      for (std::size_t b = a + 1; b < 5; ++b) {
        const double distance = (tick[a] - tick[b]).norm();
        all = std::min(all, distance);
        if (a > 0) {
          neighbours = std::min(neighbours, distance);
        }
      }
    }
  }
  EXPECT_NEAR(summary.min_pair_separation, all, 1e-12);
  EXPECT_NEAR(summary.min_neighbour_separation, neighbours, 1e-12);
  EXPECT_DOUBLE_EQ(summary.perimeter, 1.0);  // alpha ||d|| = 0.2 x 5 m
}

TEST(VehicleResponse, SaturatesLagsAndScales) {
  VehicleSpec spec;
  spec.acceleration_limit = 2.0;
  spec.input_gain = 0.5;
  spec.actuator_lag = 0.1;
  VehicleResponse<Eigen::Vector2d> vehicle(spec, 0.01, 2);
  const double blend = 1.0 - std::exp(-0.1);
  Eigen::Vector2d z = Eigen::Vector2d::Zero();
  for (int tick = 0; tick < 50; ++tick) {
    const Eigen::Vector2d command(3.0 * tick, -4.0 * tick);  // norm 5 tick > 2 from tick 1
    const Eigen::Vector2d saturated =
        tick == 0 ? command : Eigen::Vector2d(command * (2.0 / command.norm()));
    z += blend * (saturated - z);
    const Eigen::Vector2d applied = vehicle.apply(command);
    EXPECT_NEAR((applied - 0.5 * z).norm(), 0.0, 1e-12) << tick;
    EXPECT_LE(applied.norm(), 0.5 * 2.0 + 1e-12);
  }
  VehicleResponse<Eigen::Vector2d> ideal(VehicleSpec{}, 0.01, 2);
  const Eigen::Vector2d command(1e300, -3.0);
  EXPECT_EQ(ideal.apply(command), command);  // no limit, no lag, gain 1: unchanged
}

TEST(Gusts, AreSeededPoissonPulsesWithinTheirBounds) {
  GustSpec gusts;
  gusts.rate = 0.5;
  gusts.magnitude = 3.0;
  gusts.min_duration = 0.2;
  gusts.max_duration = 1.0;
  gusts.start = 10.0;
  gusts.end = 2010.0;
  const AgentModel model = makeDoubleIntegrator(2);
  const std::vector<Pulse> a = gustPulses(gusts, 7, 3, model, 5000.0);
  // 1000 expected; a Poisson count within 5 standard deviations (5 x 31.6)
  EXPECT_NEAR(static_cast<double>(a.size()), 1000.0, 160.0);
  Eigen::Vector2d mean_direction = Eigen::Vector2d::Zero();
  for (const Pulse& pulse : a) {
    EXPECT_GE(pulse.start, 10.0);
    EXPECT_LE(pulse.end, 2010.0);
    EXPECT_LE(pulse.end - pulse.start, 1.0 + 1e-12);
    ASSERT_EQ(pulse.vector.size(), 4);
    EXPECT_EQ(pulse.vector.head<2>().norm(), 0.0);  // B g: the velocity rates only
    EXPECT_LE(pulse.vector.tail<2>().norm(), 3.0 + 1e-12);
    mean_direction += pulse.vector.tail<2>().normalized();
  }
  EXPECT_LT((mean_direction / static_cast<double>(a.size())).norm(), 0.15);  // no preferred way
  const std::vector<Pulse> again = gustPulses(gusts, 7, 3, model, 5000.0);
  ASSERT_EQ(again.size(), a.size());
  EXPECT_EQ(again.front().vector, a.front().vector);
  EXPECT_NE(gustPulses(gusts, 8, 3, model, 5000.0).front().start, a.front().start);
  EXPECT_NE(gustPulses(gusts, 7, 4, model, 5000.0).front().start, a.front().start);
  gusts.rate = 0.0;
  EXPECT_TRUE(gustPulses(gusts, 7, 3, model, 5000.0).empty());
}

TEST(WorldRandom, IsTheCounterBasedSplitMix64Draw) {
  // U = (splitmix64(splitmix64(seed) ^ (stream << 40 | count)) >> 11) 2^-53, as the SciPy
  // reference draws it; N by Box-Muller on counts 2c and 2c + 1.
  EXPECT_DOUBLE_EQ(worldUniform(0, 0, 0),
                   static_cast<double>(splitMix64(splitMix64(0)) >> 11U) / 9007199254740992.0);
  const double a = worldUniform(5, 9, 6);
  const double b = worldUniform(5, 9, 7);
  EXPECT_DOUBLE_EQ(worldNormal(5, 9, 3),
                   std::sqrt(-2.0 * std::log(1.0 - a)) * std::cos(6.283185307179586 * b));
}

TEST(MeasurementNoise, HasTheConfiguredSpreadPerEntry) {
  WorldSpec world;
  world.configured = true;
  world.seed = 11;
  world.noise_position = 0.1;
  world.noise_velocity = 0.02;
  for (int entry = 0; entry < 4; ++entry) {
    double sum = 0.0;
    double squares = 0.0;
    const int draws = 20000;
    for (long tick = 0; tick < draws; ++tick) {
      const double noise = measurementNoise(world, 2, tick, entry, 4, 2);
      sum += noise;
      squares += noise * noise;
    }
    const double sigma = entry < 2 ? 0.1 : 0.02;
    EXPECT_NEAR(sum / draws, 0.0, 5.0 * sigma / std::sqrt(draws)) << entry;
    EXPECT_NEAR(std::sqrt(squares / draws), sigma, 0.03 * sigma) << entry;
  }
  world.noise_velocity = 0.0;
  EXPECT_EQ(measurementNoise(world, 2, 5, 3, 4, 2), 0.0);
}

TEST(World, NoiseAndVehiclesChangeTheRunAndSeedsRepeatIt) {
  const std::vector<std::string> noisy{"world={seed: 3, measurement_noise: {position: 0.05}}"};
  const FormationSummary a = run("crowd_v4_gust.yaml", noisy);
  expectSameRun(a, run("crowd_v4_gust.yaml", noisy));
  const FormationSummary quiet = run("crowd_v4_gust.yaml", {"world={}"});
  EXPECT_NE(a.followers[0].max_xi, quiet.followers[0].max_xi);
  const FormationSummary lagging =
      run("crowd_v4_gust.yaml", {"world={vehicle: {actuator_lag: 0.3, input_gain: 0.8}}"});
  EXPECT_NE(lagging.followers[0].max_xi, quiet.followers[0].max_xi);
}

TEST(Neighbours, KeepTheGustedFollowerOutOfItsSiblingsPerimeter) {
  // The V of 4 with the gust on follower 2: inside without formation.neighbours, outside with
  // it (a_b + A_n = the 3 m/s^2 limit; A_n = 2 m/s^2, what the gust leaves follower 2 after its
  // vehicle's 3 m/s^2).
  std::vector<std::string> limited{"controller.acceleration_limit=3"};
  const FormationSummary alone = run("crowd_v4_gust.yaml", limited);
  std::vector<std::string> protected_sets = limited;
  protected_sets.emplace_back(
      "formation.neighbours={braking_acceleration: 1, neighbour_acceleration: 2, rate: 1}");
  const FormationSummary guarded = run("crowd_v4_gust.yaml", protected_sets);
  EXPECT_LT(alone.min_pair_separation, alone.perimeter);
  EXPECT_GE(guarded.min_pair_separation, guarded.perimeter);
  EXPECT_EQ(guarded.pairs_inside_perimeter, 0);
  // In calm weather nothing comes near: the barriers never bind and the run is the same.
  limited.emplace_back("world.followers=[]");
  protected_sets.emplace_back("world.followers=[]");
  expectSameRun(run("crowd_v4_gust.yaml", limited), run("crowd_v4_gust.yaml", protected_sets));
}

TEST(NeighbourKeys, EachBadValueIsRefusedByName) {
  auto keyOf = [](const std::string& set) {
    return keyOfError({"controller.acceleration_limit=3", set});
  };
  EXPECT_EQ(keyOf("formation.neighbours={braking_acceleration: 2, neighbour_acceleration: 2}"),
            "formation.neighbours.braking_acceleration");
  EXPECT_EQ(keyOf("formation.neighbours={rate: -1}"), "formation.neighbours.rate");
  EXPECT_EQ(keyOf("formation.neighbours={max_neighbours: 0}"),
            "formation.neighbours.max_neighbours");
  EXPECT_EQ(keyOf("formation.neighbours={radius: .nan}"), "formation.neighbours.radius");
  EXPECT_EQ(keyOf("formation.neighbours={reach: 3}"), "formation.neighbours.reach");
  EXPECT_EQ(keyOf("formation.neighbours={}"), "");
}

TEST(WorldKeys, EachBadValueIsRefusedByName) {
  EXPECT_EQ(keyOfError({"world.vehicle.acceleration_limit=0"}), "world.vehicle.acceleration_limit");
  EXPECT_EQ(keyOfError({"world.vehicle.input_gain=-1"}), "world.vehicle.input_gain");
  EXPECT_EQ(keyOfError({"world.vehicle.actuator_lag=.nan"}), "world.vehicle.actuator_lag");
  EXPECT_EQ(keyOfError({"world.followers.0.index=5"}), "world.followers.0.index");
  EXPECT_EQ(keyOfError({"world.followers=[{index: 1}, {index: 1}]"}), "world.followers.1.index");
  EXPECT_EQ(keyOfError({"world.followers.0.disturbance.0.vector=[1, 2]"}),
            "world.followers.0.disturbance.0.vector");
  EXPECT_EQ(keyOfError({"world.followers.0.vehicle={input_gain: 0}"}),
            "world.followers.0.vehicle.input_gain");
  EXPECT_EQ(keyOfError({"world.gusts={rate: -1}"}), "world.gusts.rate");
  EXPECT_EQ(keyOfError({"world.gusts={min_duration: 2, max_duration: 1}"}),
            "world.gusts.max_duration");
  EXPECT_EQ(keyOfError({"world.gusts={start: 5, end: 5}"}), "world.gusts.end");
  EXPECT_EQ(keyOfError({"world.gusts={rate: 1e6, magnitude: 1}"}), "world.gusts.rate");
  EXPECT_EQ(keyOfError({"world.measurement_noise={position: -0.1}"}),
            "world.measurement_noise.position");
  EXPECT_EQ(keyOfError({"world.seed=-1"}), "world.seed");
  EXPECT_EQ(keyOfError({"world.wind=1"}), "world.wind");
  EXPECT_EQ(keyOfError({}), "");
}

}  // namespace
}  // namespace projection_collision_avoidance
