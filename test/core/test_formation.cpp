/// Formations: the layout of chains and stars, lines and Vs, and their closed loop (no roscore).

#include <cmath>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "projection_collision_avoidance/core/FollowerConfiguration.hpp"
#include "projection_collision_avoidance/core/Formation.hpp"
#include "projection_collision_avoidance/core/ParameterError.hpp"
#include "projection_collision_avoidance/scenario/ScenarioLoader.hpp"
#include "projection_collision_avoidance/sim/SampledSimulator.hpp"

#include "EigenTestHelpers.hpp"
#include "TestScenarios.hpp"

namespace projection_collision_avoidance {
namespace {

using testing::scenarioPath;

constexpr double kPi = 3.141592653589793;

std::string keyOfError(const FormationSpec& spec, const AgentModel& model) {
  try {
    spec.validate(model);
  } catch (const ParameterError& error) {
    return error.key();
  }
  return "";
}

std::vector<FormationMember> layout(FormationTopology topology, FormationShape shape, int n,
                                    const Eigen::VectorXd& d) {
  FormationSpec spec;
  spec.configured = true;
  spec.followers = n;
  spec.topology = topology;
  spec.shape = shape;
  Eigen::VectorXd leader = Eigen::VectorXd::Zero(d.size());
  leader(0) = 100.0;
  const Eigen::VectorXd follower = leader - d;  // xi_0 = 0
  return layoutFormation(spec, d, leader, follower);
}

TEST(FormationLayout, StarLineStacksTheSeparation) {
  const Eigen::Vector2d d(5.0, 0.0);
  const auto members = layout(FormationTopology::kStar, FormationShape::kLine, 3, d);
  ASSERT_EQ(members.size(), 3u);
  for (int i = 1; i <= 3; ++i) {
    const FormationMember& m = members[i - 1];
    EXPECT_EQ(m.index, i);
    EXPECT_EQ(m.name, "follower_" + std::to_string(i));
    EXPECT_EQ(m.target, 0);
    EXPECT_EQ(m.target_name, "leader");
    EXPECT_MATRIX_NEAR(m.separation, Eigen::VectorXd(i * d), 0.0);
    EXPECT_MATRIX_NEAR(m.initial_state, Eigen::Vector2d(100.0 - 5.0 * i, 0.0), 1e-12);
  }
}

TEST(FormationLayout, ChainLineLooksAtTheAgentAhead) {
  const Eigen::Vector2d d(5.0, 0.0);
  const auto members = layout(FormationTopology::kChain, FormationShape::kLine, 4, d);
  for (int i = 1; i <= 4; ++i) {
    const FormationMember& m = members[i - 1];
    EXPECT_EQ(m.target, i - 1);
    EXPECT_EQ(m.target_name, i == 1 ? "leader" : "follower_" + std::to_string(i - 1));
    EXPECT_MATRIX_NEAR(m.separation, Eigen::VectorXd(d), 0.0);
    EXPECT_MATRIX_NEAR(m.initial_state, Eigen::Vector2d(100.0 - 5.0 * i, 0.0), 1e-12);
  }
}

TEST(FormationLayout, VArmsTurnTheSeparationBothWays) {
  Eigen::VectorXd d = Eigen::VectorXd::Zero(4);
  d(0) = 5.0;
  const double angle = kPi / 6.0;
  const auto star = layout(FormationTopology::kStar, FormationShape::kV, 5, d);
  const auto chain = layout(FormationTopology::kChain, FormationShape::kV, 5, d);
  for (int i = 1; i <= 5; ++i) {
    const int rank = (i + 1) / 2;
    const double side = i % 2 == 1 ? 1.0 : -1.0;
    Eigen::VectorXd arm = Eigen::VectorXd::Zero(4);
    arm(0) = 5.0 * std::cos(angle);
    arm(1) = 5.0 * std::sin(side * angle);
    EXPECT_MATRIX_NEAR(star[i - 1].separation, Eigen::VectorXd(rank * arm), 1e-12) << i;
    EXPECT_EQ(star[i - 1].target, 0);
    EXPECT_MATRIX_NEAR(chain[i - 1].separation, arm, 1e-12) << i;
    EXPECT_EQ(chain[i - 1].target, i > 2 ? i - 2 : 0);
    // The star and the chain put every follower on the same slot.
    EXPECT_MATRIX_NEAR(star[i - 1].initial_state, chain[i - 1].initial_state, 1e-12) << i;
  }
}

// A follower configured alone (FollowerConfiguration, as the follower node is) gets the slot,
// target and name that the layout of the whole formation gives it.
TEST(FormationLayout, OneMembersSlotIsItsSlotInTheLayout) {
  Eigen::VectorXd d = Eigen::VectorXd::Zero(4);
  d(0) = 5.0;
  for (const FormationTopology topology : {FormationTopology::kStar, FormationTopology::kChain}) {
    for (const FormationShape shape : {FormationShape::kLine, FormationShape::kV}) {
      FollowerConfiguration configuration;
      configuration.controller.separation = d;
      configuration.formation.configured = true;
      configuration.formation.followers = 7;
      configuration.formation.topology = topology;
      configuration.formation.shape = shape;
      const auto all = layout(topology, shape, 7, d);
      for (int i = 1; i <= 7; ++i) {
        const FormationMember one = configuration.member(i, "~formation_index");
        EXPECT_EQ(one.name, all[i - 1].name);
        EXPECT_EQ(one.target, all[i - 1].target);
        EXPECT_EQ(one.target_name, all[i - 1].target_name);
        EXPECT_EQ(one.separation, all[i - 1].separation) << i;
      }
      for (const int outside : {0, 8}) {
        try {
          configuration.member(outside, "~formation_index");
          ADD_FAILURE() << "index " << outside << " accepted";
        } catch (const ParameterError& error) {
          EXPECT_EQ(error.key(), "~formation_index");
        }
      }
    }
  }
}

TEST(FormationLayout, KeepsTheScenariosInitialRelativeError) {
  FormationSpec spec;
  spec.configured = true;
  spec.followers = 3;
  spec.topology = FormationTopology::kChain;
  const Eigen::Vector2d d(5.0, 0.0);
  const Eigen::Vector2d leader(5.0, 1.0);
  const Eigen::Vector2d follower(0.5, 0.0);  // xi_0 = [-0.5, 1]
  const auto members = layoutFormation(spec, d, leader, follower);
  Eigen::VectorXd ahead = leader;
  for (const FormationMember& m : members) {
    EXPECT_MATRIX_NEAR(Eigen::VectorXd(ahead - m.initial_state - m.separation),
                       Eigen::VectorXd(leader - follower - d), 1e-12);
    ahead = m.initial_state;
  }
}

TEST(FormationLayout, ThePairIsOneFollowerNamedFollower) {
  const FormationSpec spec;  // no formation section
  const auto members = layoutFormation(spec, Eigen::Vector2d(5.0, 0.0), Eigen::Vector2d(5.0, 0.0),
                                       Eigen::Vector2d(0.0, 0.0));
  ASSERT_EQ(members.size(), 1u);
  EXPECT_EQ(members[0].name, "follower");
  EXPECT_EQ(members[0].target_name, "leader");
}

TEST(FormationSpec, RefusesWhatItCannotLayOut) {
  FormationSpec spec;
  spec.followers = 0;
  EXPECT_EQ(keyOfError(spec, makeDoubleIntegrator(1)), "formation.followers");
  spec.followers = FormationSpec::kMaxFollowers + 1;
  EXPECT_EQ(keyOfError(spec, makeDoubleIntegrator(1)), "formation.followers");
  spec.followers = 3;
  spec.shape = FormationShape::kV;
  EXPECT_EQ(keyOfError(spec, makeDoubleIntegrator(1)), "formation.shape");
  EXPECT_EQ(keyOfError(spec, makeDoubleIntegrator(2)), "");
  EXPECT_EQ(keyOfError(spec, makeDoubleIntegrator(3)), "");
  for (const double angle : {0.0, -0.1, kPi / 2.0, std::nan("")}) {
    spec.half_angle = angle;
    EXPECT_EQ(keyOfError(spec, makeDoubleIntegrator(2)), "formation.half_angle") << angle;
  }
}

TEST(FormationScenario, LoadsTheSectionAndNamesBadKeys) {
  const Scenario scenario = loadScenarioFile(scenarioPath("figure_eight_2d.yaml"),
                                             {"formation.followers=3", "formation.topology=chain",
                                              "formation.shape=v", "formation.half_angle=0.4"});
  EXPECT_TRUE(scenario.formation.configured);
  EXPECT_EQ(scenario.formation.followers, 3);
  EXPECT_EQ(scenario.formation.topology, FormationTopology::kChain);
  EXPECT_EQ(scenario.formation.shape, FormationShape::kV);
  EXPECT_DOUBLE_EQ(scenario.formation.half_angle, 0.4);
  const auto keyOf = [](const std::vector<std::string>& overrides) -> std::string {
    try {
      loadScenarioFile(scenarioPath("paper_run2.yaml"), overrides);
    } catch (const ParameterError& error) {
      return error.key();
    }
    return "";
  };
  EXPECT_EQ(keyOf({"formation.followers=2", "formation.topology=ring"}), "formation.topology");
  EXPECT_EQ(keyOf({"formation.followers=2", "formation.shape=v"}), "formation.shape");
  EXPECT_EQ(keyOf({"formation.followers=2.5"}), "formation.followers");
  EXPECT_EQ(keyOf({"formation.topology=chain"}), "formation.followers");  // required
  EXPECT_EQ(keyOf({"formation.followers=2", "formation.spacing=3"}), "formation.spacing");
}

TEST(FormationRun, StarFollowersRepeatThePairWhileTheProjectionRests) {
  // In Run 2 the estimate stays inside xi_max (it never reaches the projection), and the
  // relative dynamics do not depend on d: every follower of a star sees the pair's ||xi||.
  const std::vector<std::string> fast = {"controller.control_rate=100"};
  const SimulationSummary pair = simulate(loadScenarioFile(scenarioPath("paper_run2.yaml"), fast));
  ASSERT_LT(pair.max_xi_hat, pair.xi_max);
  std::vector<std::string> star = fast;
  star.push_back("formation.followers=3");
  const FormationSummary formation =
      simulateFormation(loadScenarioFile(scenarioPath("paper_run2.yaml"), star));
  ASSERT_EQ(formation.followers.size(), 3u);
  for (std::size_t i = 0; i < 3; ++i) {
    const SimulationSummary& s = formation.followers[i];
    EXPECT_NEAR(s.max_xi, pair.max_xi, 1e-9) << i;
    EXPECT_DOUBLE_EQ(s.xi_max, 4.0 * static_cast<double>(i + 1));
    EXPECT_NEAR(s.min_separation, pair.min_separation + 5.0 * static_cast<double>(i), 1e-9);
  }
  EXPECT_NEAR(formation.min_pair_separation, pair.min_separation, 1e-9);
}

TEST(FormationRun, SharedAccelerationsCarryAChainWithoutError) {
  // The leader drives a sinusoid; with its acceleration fed forward (follower 1) and each
  // follower's command fed forward to the one behind it, the zero-order-held inputs match
  // exactly and no relative error appears. Without sharing, every follower lags.
  const std::vector<std::string> base = {
      "controller.control_rate=100", "leader.disturbance=[]",
      "leader.input={sinusoids: [{amplitude: [1.0], frequency: 0.1}]}", "formation.followers=3",
      "formation.topology=chain"};
  std::vector<std::string> shared = base;
  shared.push_back("controller.leader_information.command=true");
  const FormationSummary blind =
      simulateFormation(loadScenarioFile(scenarioPath("paper_run2.yaml"), base));
  const FormationSummary told =
      simulateFormation(loadScenarioFile(scenarioPath("paper_run2.yaml"), shared));
  for (std::size_t i = 0; i < 3; ++i) {
    EXPECT_GT(blind.followers[i].max_xi, 0.1) << i;
    EXPECT_LT(told.followers[i].max_xi, 1e-9) << i;
  }
}

TEST(FormationRun, SimulateRefusesMoreThanOneFollower) {
  const Scenario scenario =
      loadScenarioFile(scenarioPath("paper_run2.yaml"), {"formation.followers=2"});
  try {
    simulate(scenario);
    FAIL() << "simulate() ran a formation of two";
  } catch (const ParameterError& error) {
    EXPECT_EQ(error.key(), "formation.followers");
  }
}

}  // namespace
}  // namespace projection_collision_avoidance
