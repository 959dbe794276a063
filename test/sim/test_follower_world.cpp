/// FollowerWorld, the world section as a plant outside cf_sim applies it to one follower (the
/// plant node): without a world it is nothing; with one, a plant driven the plant node's way
/// (GenericDimensions, the held command through the true vehicle, then integrated) retraces
/// cf_sim's followers; the noise is cf_sim's draw; and the relative state of a sensed agent,
/// by the radius (no roscore).

#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <gtest/gtest.h>

#include "projection_collision_avoidance/core/TypeDefs.hpp"
#include "projection_collision_avoidance/scenario/ScenarioLoader.hpp"
#include "projection_collision_avoidance/sim/AgentIntegrator.hpp"
#include "projection_collision_avoidance/sim/FollowerWorld.hpp"
#include "projection_collision_avoidance/sim/SampledSimulator.hpp"

#include "TestScenarios.hpp"

namespace projection_collision_avoidance {
namespace {

using testing::scenarioPath;

Scenario crowd(const std::vector<std::string>& overrides) {
  return loadScenarioFile(scenarioPath("crowd_v4_gust.yaml"), overrides);
}

TEST(FollowerWorld, WithoutAWorldIsNothing) {
  const Scenario scenario = crowd({"world=~"});
  for (int index = 1; index <= 4; ++index) {
    FollowerWorld world(scenario.world, index, scenario.controller.model, scenario.duration, 0.01);
    EXPECT_FALSE(world.disturbed());
    EXPECT_FALSE(world.hasVehicle());
    EXPECT_FALSE(world.noisy());
    EXPECT_TRUE(world.disturbance().pulses.empty());
    const Eigen::VectorXd command = Eigen::Vector2d(1e300, -3.0);
    EXPECT_EQ(world.apply(command), command);  // unchanged, bit for bit
    Eigen::VectorXd relative = Eigen::Vector4d(1.0, 2.0, 3.0, 4.0);
    const Eigen::VectorXd before = relative;
    world.addNoise(7, &relative);
    EXPECT_EQ(relative, before);
  }
}

TEST(FollowerWorld, DisturbanceAndVehicleAreCfSims) {
  const Scenario scenario = crowd({});
  // Follower 2 has the file's pulse; the others only gusts (none here) and world.vehicle's limit.
  FollowerWorld second(scenario.world, 2, scenario.controller.model, scenario.duration, 0.01);
  ASSERT_EQ(second.disturbance().pulses.size(), 1U);
  EXPECT_EQ(second.disturbance().pulses[0].start, 20.0);
  EXPECT_EQ(second.disturbance().pulses[0].end, 23.0);
  EXPECT_TRUE(second.disturbed());
  EXPECT_TRUE(second.hasVehicle());
  FollowerWorld first(scenario.world, 1, scenario.controller.model, scenario.duration, 0.01);
  EXPECT_FALSE(first.disturbed());
  const Eigen::VectorXd command = Eigen::Vector2d(6.0, -8.0);  // 10 m/s^2 > 3: saturated
  EXPECT_NEAR((first.apply(command) - 0.3 * command).norm(), 0.0, 1e-12);
}

/// Replays each of cf_sim's followers as the plant node drives it: its commands held over each
/// tick through FollowerWorld::apply(), integrated by a GenericDimensions AgentIntegrator with
/// FollowerWorld::disturbance(); every tick's state is cf_sim's.
void expectPlantRetracesCfSim(const std::vector<std::string>& overrides) {
  const Scenario scenario = crowd(overrides);
  const int followers = scenario.formation.followers;
  std::vector<std::vector<Eigen::VectorXd>> states(static_cast<std::size_t>(followers));
  std::vector<std::vector<Eigen::VectorXd>> commands(static_cast<std::size_t>(followers));
  simulateFormation(scenario, [&](int member, const SimulationSample& sample) {
    states[static_cast<std::size_t>(member)].push_back(sample.follower_state);
    commands[static_cast<std::size_t>(member)].push_back(sample.controller.command);
  });
  const double period = 1.0 / scenario.controller.control_rate;
  for (int member = 0; member < followers; ++member) {
    const std::vector<Eigen::VectorXd>& expected = states[static_cast<std::size_t>(member)];
    const std::vector<Eigen::VectorXd>& held = commands[static_cast<std::size_t>(member)];
    ASSERT_GT(expected.size(), 2U);
    FollowerWorld world(scenario.world, member + 1, scenario.controller.model, scenario.duration,
                        period);
    AgentIntegrator<GenericDimensions> plant(scenario.controller.model, period, expected.front(),
                                             world.disturbance());
    double largest = 0.0;
    for (std::size_t k = 0; k < expected.size(); ++k) {
      largest = std::max(largest, (plant.state() - expected[k]).cwiseAbs().maxCoeff());
      plant.advance(static_cast<double>(k) * period, world.apply(held[k]));
    }
    // Dynamic and fixed-size Eigen products may round apart in the last bit.
    EXPECT_LE(largest, 1e-9) << "follower " << member + 1;
  }
}

TEST(FollowerWorld, APlantDrivenThroughItRetracesCfSim) {
  // The file's pulse on follower 2 and the limited vehicle; then a lag, a gain and gusts.
  expectPlantRetracesCfSim({"simulation.duration=26"});
  expectPlantRetracesCfSim(
      {"simulation.duration=12",
       "world={seed: 4, vehicle: {acceleration_limit: 3.0, input_gain: 0.8, actuator_lag: 0.3}, "
       "gusts: {rate: 0.5, magnitude: 4.0}, followers: [{index: 3, sinusoids: [{amplitude: [0, "
       "0, 0.5, 0], frequency: 0.2, phase: 0}]}]}"});
}

TEST(FollowerWorld, NoiseIsCfSimsDrawOfTheTick) {
  const Scenario scenario =
      crowd({"world={seed: 3, measurement_noise: {position: 0.05, velocity: 0.02}}"});
  FollowerWorld world(scenario.world, 3, scenario.controller.model, scenario.duration, 0.01);
  ASSERT_TRUE(world.noisy());
  for (const long tick : {0L, 1L, 250L}) {
    Eigen::VectorXd relative = Eigen::VectorXd::Zero(4);
    world.addNoise(tick, &relative);
    for (int e = 0; e < 4; ++e) {
      EXPECT_EQ(relative(e), measurementNoise(scenario.world, 3, tick, e, 4, 2)) << tick;
      EXPECT_NE(relative(e), 0.0);
    }
  }
}

TEST(RelativeStateWithin, IsTheOtherMinusOwnWithinTheRadius) {
  const Eigen::Vector4d own(1.0, 2.0, 0.5, -0.5);   // [p; v], 2 axes
  const Eigen::Vector4d other(4.0, 6.0, 0.0, 1.0);  // 5 m away
  std::vector<double> position(2);
  std::vector<double> velocity(2);
  EXPECT_TRUE(relativeStateWithin(own, other, 2, std::numeric_limits<double>::infinity(), &position,
                                  &velocity));
  EXPECT_EQ(position, (std::vector<double>{3.0, 4.0}));                        // p_j - p_i
  EXPECT_EQ(velocity, (std::vector<double>{-0.5, 1.5}));                       // v_j - v_i
  EXPECT_TRUE(relativeStateWithin(own, other, 2, 5.0, &position, &velocity));  // on the radius
  EXPECT_FALSE(relativeStateWithin(own, other, 2, 4.999, &position, &velocity));
  const Eigen::Vector4d lost(std::nan(""), 0.0, 0.0, 0.0);
  EXPECT_FALSE(relativeStateWithin(own, lost, 2, std::numeric_limits<double>::infinity(), &position,
                                   &velocity));
  // 1 and 3 axes.
  std::vector<double> p1(1);
  std::vector<double> v1(1);
  EXPECT_TRUE(
      relativeStateWithin(Eigen::Vector2d(2.0, 1.0), Eigen::Vector2d(-1.0, 0.0), 1, 3.0, &p1, &v1));
  EXPECT_EQ(p1[0], -3.0);
  EXPECT_EQ(v1[0], -1.0);
  std::vector<double> p3(3);
  std::vector<double> v3(3);
  Eigen::VectorXd a = Eigen::VectorXd::Zero(6);
  Eigen::VectorXd b(6);
  b << 1.0, 2.0, 2.0, 0.1, 0.2, 0.3;  // 3 m away
  EXPECT_FALSE(relativeStateWithin(a, b, 3, 2.5, &p3, &v3));
  EXPECT_EQ(p3, (std::vector<double>{1.0, 2.0, 2.0}));
  EXPECT_EQ(v3, (std::vector<double>{0.1, 0.2, 0.3}));
}

}  // namespace
}  // namespace projection_collision_avoidance
