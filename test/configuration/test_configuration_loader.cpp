/// A follower's configuration read from a scenario file (src/configuration): the same controller
/// and formation as the whole scenario's, the simulation's sections not read, a file with the
/// follower's sections alone, and errors naming their keys.

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "projection_collision_avoidance/configuration/ConfigurationLoader.hpp"
#include "projection_collision_avoidance/core/ParameterError.hpp"
#include "projection_collision_avoidance/scenario/ScenarioLoader.hpp"

#include "EigenTestHelpers.hpp"
#include "TestScenarios.hpp"

namespace projection_collision_avoidance {
namespace {

using testing::scenarioPath;

std::string textOf(const std::string& path) {
  std::ifstream file(path);
  std::stringstream text;
  text << file.rdbuf();
  return text.str();
}

/// Every field of the two configurations is equal (matrices entry by entry, exactly).
void expectSame(const FollowerConfiguration& read, const FollowerConfiguration& expected) {
  const ControllerParameters& a = read.controller;
  const ControllerParameters& b = expected.controller;
  EXPECT_MATRIX_NEAR(a.model.A, b.model.A, 0.0);
  EXPECT_MATRIX_NEAR(a.model.B, b.model.B, 0.0);
  EXPECT_MATRIX_NEAR(a.model.C, b.model.C, 0.0);
  EXPECT_EQ(a.model.position_dimension, b.model.position_dimension);
  EXPECT_EQ(a.model.double_integrator_axes, b.model.double_integrator_axes);
  EXPECT_EQ(a.control_rate, b.control_rate);
  EXPECT_MATRIX_NEAR(a.separation, b.separation, 0.0);
  EXPECT_EQ(a.alpha, b.alpha);
  EXPECT_EQ(a.epsilon, b.epsilon);
  EXPECT_MATRIX_NEAR(a.baseline_gain, b.baseline_gain, 0.0);
  EXPECT_MATRIX_NEAR(a.estimator_gain, b.estimator_gain, 0.0);
  EXPECT_MATRIX_NEAR(a.lyapunov_weight, b.lyapunov_weight, 0.0);
  EXPECT_EQ(a.estimator_substeps, b.estimator_substeps);
  EXPECT_EQ(a.initial_estimate, b.initial_estimate);
  EXPECT_EQ(a.tracker_enabled, b.tracker_enabled);
  EXPECT_MATRIX_NEAR(a.tracker_gain, b.tracker_gain, 0.0);
  EXPECT_MATRIX_NEAR(a.reference_gain, b.reference_gain, 0.0);
  EXPECT_EQ(a.leader_input_in_command, b.leader_input_in_command);
  EXPECT_EQ(a.leader_input_in_estimator, b.leader_input_in_estimator);
  EXPECT_EQ(a.leader_disturbance_shared, b.leader_disturbance_shared);
  EXPECT_EQ(a.feedforward_gain, b.feedforward_gain);
  EXPECT_EQ(a.feedforward_time_constant, b.feedforward_time_constant);
  EXPECT_EQ(a.time_headway, b.time_headway);
  EXPECT_EQ(a.acceleration_limit, b.acceleration_limit);
  EXPECT_EQ(a.jerk_limit, b.jerk_limit);
  EXPECT_MATRIX_NEAR(a.fallback_gain, b.fallback_gain, 0.0);
  EXPECT_EQ(read.formation.configured, expected.formation.configured);
  EXPECT_EQ(read.formation.followers, expected.formation.followers);
  EXPECT_EQ(read.formation.topology, expected.formation.topology);
  EXPECT_EQ(read.formation.shape, expected.formation.shape);
  EXPECT_EQ(read.formation.half_angle, expected.formation.half_angle);
}

/// Expects reading the paper's Run 2 with @p overrides to fail naming @p key.
void expectKey(const std::vector<std::string>& overrides, const std::string& key,
               const std::string& text = "") {
  try {
    parseFollowerConfiguration(textOf(scenarioPath("paper_run2.yaml")), overrides);
    ADD_FAILURE() << "accepted; expected an error naming " << key;
  } catch (const ParameterError& error) {
    EXPECT_EQ(error.key(), key) << error.what();
    EXPECT_NE(std::string(error.what()).find(text), std::string::npos) << error.what();
  }
}

TEST(ConfigurationLoader, ReadsWhatTheWholeScenarioReadsFromEveryShippedFile) {
  int files = 0;
  for (const auto& entry : std::filesystem::directory_iterator(SCENARIO_DIR)) {
    if (entry.path().extension() != ".yaml") {
      continue;
    }
    SCOPED_TRACE(entry.path().string());
    expectSame(loadFollowerConfigurationFile(entry.path().string()),
               loadScenarioFile(entry.path().string()).followerConfiguration());
    ++files;
  }
  EXPECT_GE(files, 6);
}

TEST(ConfigurationLoader, AppliesOverridesAsTheScenarioLoaderDoes) {
  const std::vector<std::string> overrides{"controller.alpha=0.3", "formation={followers: 4}",
                                           "controller.tracker.enabled=false"};
  const std::string text = textOf(scenarioPath("paper_run2.yaml"));
  const FollowerConfiguration read = parseFollowerConfiguration(text, overrides);
  EXPECT_EQ(read.controller.alpha, 0.3);
  EXPECT_EQ(read.formation.followers, 4);
  EXPECT_FALSE(read.controller.tracker_enabled);
  expectSame(read, parseScenario(text, overrides).followerConfiguration());
}

TEST(ConfigurationLoader, ReadsAFileWithTheFollowersSectionsAlone) {
  // A vehicle's file: no leader, follower, simulation or link section.
  const std::vector<std::string> without_simulation{"leader=null", "follower=null",
                                                    "simulation=null"};
  const std::string text = textOf(scenarioPath("platoon_run2.yaml"));
  const FollowerConfiguration alone = parseFollowerConfiguration(text, without_simulation);
  expectSame(alone, parseScenario(text).followerConfiguration());
  // The whole scenario needs them.
  EXPECT_THROW(parseScenario(text, without_simulation), ParameterError);
}

TEST(ConfigurationLoader, LeavesTheSimulationsSectionsToTheScenarioLoader) {
  // Values only a simulation reads: the follower's configuration does not look at them.
  const std::vector<std::string> simulation_only{"leader.initial_state=[1, 2, 3]",
                                                 "simulation.duration=-1", "follower=7",
                                                 "controller.leader_information.link.dropout=2"};
  const std::string text = textOf(scenarioPath("platoon_run2.yaml"));
  expectSame(parseFollowerConfiguration(text, simulation_only),
             parseScenario(text).followerConfiguration());
  for (const std::string& override : simulation_only) {
    EXPECT_THROW(parseScenario(text, {override}), ParameterError) << override;
  }
}

TEST(ConfigurationLoader, NamesTheKeyOfEveryErrorInItsSections) {
  expectKey({"controller.alpah=0.2"}, "controller.alpah", "unknown key");
  expectKey({"extra=1"}, "extra", "unknown key");
  expectKey({"model.type=triple_integrator"}, "model.type", "must be double_integrator");
  expectKey({"controller.alpha=1.5"}, "controller.alpha");
  expectKey({"formation.followers=0"}, "formation.followers");
  // A V needs 2 or 3 axes; Run 2 has 1.
  expectKey({"formation={followers: 2, shape: v}"}, "formation.shape");
  expectKey({"controller=null"}, "controller", "missing");
}

TEST(ConfigurationLoader, RunsTheCallersCheckBeforeTheDesignsDerivedChecks) {
  ConfigurationLoadOptions options;
  options.check = [](const FollowerConfiguration& configuration) {
    if (configuration.controller.control_rate < 10.0) {
      throw ParameterError("controller.control_rate", "too slow for this caller");
    }
  };
  // At 1 Hz the design would name estimator.substeps; the caller's check comes first.
  try {
    parseFollowerConfiguration(textOf(scenarioPath("paper_run2.yaml")),
                               {"controller.control_rate=1"}, options);
    ADD_FAILURE() << "accepted";
  } catch (const ParameterError& error) {
    EXPECT_EQ(error.key(), "controller.control_rate") << error.what();
  }
}

TEST(ConfigurationLoader, StopsWhenCancelled) {
  ConfigurationLoadOptions options;
  options.cancelled = [] { return true; };
  EXPECT_THROW(parseFollowerConfiguration(textOf(scenarioPath("paper_run2.yaml")), {}, options),
               ScenarioLoadCancelled);
}

}  // namespace
}  // namespace projection_collision_avoidance
