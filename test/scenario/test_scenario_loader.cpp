/// The YAML scenario loader: the paper's files, overrides, every error naming its key, the size
/// limit of files, and the caller's checks running before the design's derived ones.

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <system_error>
#include <vector>

#include <gtest/gtest.h>
#include <unistd.h>

#include "projection_collision_avoidance/core/ParameterError.hpp"
#include "projection_collision_avoidance/scenario/ScenarioLoader.hpp"

#include "EigenTestHelpers.hpp"
#include "TestScenarios.hpp"

namespace projection_collision_avoidance {
namespace {

using testing::scenarioPath;

std::string paperText() {
  std::ifstream file(scenarioPath("paper_run2.yaml"));
  std::stringstream text;
  text << file.rdbuf();
  return text.str();
}

/// Expects loading with @p overrides to fail with @p key, the message containing @p text.
void expectKey(const std::vector<std::string>& overrides, const std::string& key,
               const std::string& text = "") {
  try {
    parseScenario(paperText(), overrides);
    ADD_FAILURE() << "accepted; expected an error naming " << key;
  } catch (const ParameterError& error) {
    EXPECT_EQ(error.key(), key) << error.what();
    EXPECT_NE(std::string(error.what()).find(text), std::string::npos) << error.what();
  }
}

TEST(ScenarioLoader, ReadsThePapersRun) {
  const Scenario s = loadScenarioFile(scenarioPath("paper_run2.yaml"));
  const ControllerParameters& p = s.controller;
  EXPECT_EQ(p.model.stateDimension(), 2);
  EXPECT_EQ(p.model.double_integrator_axes, 1);
  EXPECT_DOUBLE_EQ(p.control_rate, 1000.0);
  EXPECT_MATRIX_NEAR(p.separation, Eigen::Vector2d(5.0, 0.0), 0.0);
  EXPECT_DOUBLE_EQ(p.alpha, 0.2);
  EXPECT_DOUBLE_EQ(p.epsilon, 0.2);
  EXPECT_MATRIX_NEAR(p.baseline_gain, Eigen::RowVector2d(1.0, 1.4), 1e-15);
  EXPECT_MATRIX_NEAR(p.estimator_gain, Eigen::MatrixXd(-5.0 * Eigen::Matrix2d::Identity()), 0.0);
  EXPECT_MATRIX_NEAR(p.lyapunov_weight, Eigen::MatrixXd(Eigen::Matrix2d::Identity()), 0.0);
  EXPECT_TRUE(p.tracker_enabled);
  EXPECT_MATRIX_NEAR(p.tracker_gain, Eigen::RowVector2d(10.0, 5.0), 0.0);
  EXPECT_MATRIX_NEAR(p.reference_gain, Eigen::RowVector2d(0.0, 0.0), 0.0);
  EXPECT_EQ(p.initial_estimate, InitialEstimate::kMeasurement);
  EXPECT_MATRIX_NEAR(s.leader_initial_state, Eigen::Vector2d(5.0, 0.0), 0.0);
  EXPECT_MATRIX_NEAR(s.follower_initial_state, Eigen::Vector2d(0.0, 0.0), 0.0);
  ASSERT_EQ(s.disturbance.pulses.size(), 1u);
  EXPECT_DOUBLE_EQ(s.disturbance.pulses[0].start, 20.0);
  EXPECT_DOUBLE_EQ(s.disturbance.pulses[0].end, 23.0);
  EXPECT_MATRIX_NEAR(s.disturbance.pulses[0].vector, Eigen::Vector2d(-2.0, -2.0), 0.0);
  EXPECT_TRUE(s.leader_input.pulses.empty());
  EXPECT_DOUBLE_EQ(s.duration, 60.0);
  const Scenario run1 = loadScenarioFile(scenarioPath("paper_run1.yaml"));
  EXPECT_FALSE(run1.controller.tracker_enabled);
}

TEST(ScenarioLoader, AppliesOverridesByDottedPath) {
  const Scenario s =
      parseScenario(paperText(), {"controller.alpha=0.3", "controller.tracker.enabled=false",
                                  "leader.disturbance.0.vector=[-1.5, -0.5]",
                                  "controller.estimator.gain=[[-4, 0], [0, -6]]",
                                  "leader.input={pulses: [{start: 1, end: 2, vector: [0.5]}], "
                                  "sinusoids: [{amplitude: [0.2], frequency: 0.5}]}",
                                  "controller.leader_information.command=true"});
  EXPECT_DOUBLE_EQ(s.controller.alpha, 0.3);
  EXPECT_FALSE(s.controller.tracker_enabled);
  EXPECT_MATRIX_NEAR(s.disturbance.pulses[0].vector, Eigen::Vector2d(-1.5, -0.5), 0.0);
  EXPECT_MATRIX_NEAR(s.controller.estimator_gain, (Eigen::Matrix2d() << -4, 0, 0, -6).finished(),
                     0.0);
  ASSERT_EQ(s.leader_input.pulses.size(), 1u);
  ASSERT_EQ(s.leader_input.sinusoids.size(), 1u);
  EXPECT_DOUBLE_EQ(s.leader_input.sinusoids[0].frequency, 0.5);
  EXPECT_DOUBLE_EQ(s.leader_input.sinusoids[0].phase, 0.0);
  EXPECT_TRUE(s.controller.leader_input_in_command);
  EXPECT_TRUE(std::isinf(s.controller.acceleration_limit));  // absent: no bound
  EXPECT_DOUBLE_EQ(parseScenario(paperText(), {"controller.acceleration_limit=9.81"})
                       .controller.acceleration_limit,
                   9.81);
  EXPECT_FALSE(s.controller.leader_input_in_estimator);
  EXPECT_NEAR(s.leader_input.value(1.5, 1)(0), 0.5 + 0.2 * std::sin(2.0 * M_PI * 0.75), 1e-12);
}

TEST(ScenarioLoader, PoleFormAndScalarMatrices) {
  const Scenario s = parseScenario(
      paperText(),
      {"model.dimension=2", "controller.separation=[3, 4, 0, 0]",
       "controller.baseline.natural_frequency=[1, 2]", "controller.baseline.damping=0.5",
       "controller.tracker={enabled: true, natural_frequency: 3, damping: 1}",
       "leader.initial_state=[3, 4, 0, 0]", "follower.initial_state=[0, 0, 0, 0]",
       "leader.disturbance=[]"});
  Eigen::MatrixXd G(2, 4);
  G << 1, 0, 1, 0, 0, 4, 0, 2;
  EXPECT_MATRIX_NEAR(s.controller.baseline_gain, G, 1e-15);
  Eigen::MatrixXd Ge(2, 4);
  Ge << 9, 0, 6, 0, 0, 9, 0, 6;
  EXPECT_MATRIX_NEAR(s.controller.tracker_gain, Ge, 1e-15);
  EXPECT_MATRIX_NEAR(s.controller.estimator_gain,
                     Eigen::MatrixXd(-5.0 * Eigen::Matrix4d::Identity()), 0.0);
  EXPECT_MATRIX_NEAR(s.controller.reference_gain, Eigen::MatrixXd::Zero(2, 4), 0.0);
  // 0 stands for the zero matrix of any shape; other numbers need a square matrix.
  const Scenario zero = parseScenario(paperText(), {"controller.tracker.reference_gain=0"});
  EXPECT_MATRIX_NEAR(zero.controller.reference_gain, Eigen::RowVector2d::Zero(), 0.0);
  expectKey({"controller.tracker.reference_gain=1"}, "controller.tracker.reference_gain", "square");
}

TEST(ScenarioLoader, ReadsALinearModel) {
  const Scenario s = parseScenario(
      paperText(), {"model={type: linear, A: [[0, 1], [0, -0.5]], B: [[0], [2]], "
                    "position_dimension: 1, C: [[1, 0]]}",
                    "controller.baseline={gain: [[1]]}", "controller.estimator.gain=[[-3], [-2]]",
                    "controller.tracker.gain=[[2]]", "controller.tracker.reference_gain=[[0]]"});
  EXPECT_EQ(s.controller.model.outputDimension(), 1);
  EXPECT_EQ(s.controller.model.double_integrator_axes, 0);
  EXPECT_MATRIX_NEAR(s.controller.model.B, Eigen::Vector2d(0.0, 2.0), 0.0);
}

TEST(ScenarioLoader, RefusesUnknownKeysAtEveryLevel) {
  expectKey({"controller.alpah=0.2"}, "controller.alpah", "unknown key");
  expectKey({"controller.tracker.gian=[[1, 1]]"}, "controller.tracker.gian", "unknown key");
  expectKey({"simulation.dt=0.1"}, "simulation.dt", "unknown key");
  expectKey({"leader.disturbance.0.strength=1"}, "leader.disturbance.0.strength", "unknown key");
  expectKey({"extra=1"}, "extra", "unknown key");
  expectKey({"model.A=[[0]]"}, "model.A", "unknown key");  // A belongs to linear models only
}

TEST(ScenarioLoader, RefusesMissingKeys) {
  std::string text = paperText();
  text.replace(text.find("  alpha: 0.2\n"), 13, "");
  try {
    parseScenario(text);
    ADD_FAILURE() << "accepted a scenario without alpha";
  } catch (const ParameterError& error) {
    EXPECT_EQ(error.key(), "controller.alpha");
    EXPECT_NE(std::string(error.what()).find("missing"), std::string::npos);
  }
  expectKey({"controller.tracker.enabled=~"}, "controller.tracker.enabled", "missing");
}

TEST(ScenarioLoader, RefusesWrongTypes) {
  expectKey({"controller.alpha=high"}, "controller.alpha", "a number");
  expectKey({"controller.alpha=[0.2]"}, "controller.alpha", "a number");
  expectKey({"controller.tracker.enabled=maybe"}, "controller.tracker.enabled", "true or false");
  expectKey({"controller.estimator.substeps=2.5"}, "controller.estimator.substeps", "whole");
  expectKey({"controller.separation=5"}, "controller.separation", "list of numbers");
  expectKey({"controller.baseline={gain: [1, 1.4]}"}, "controller.baseline.gain", "list of rows");
  expectKey({"controller.baseline={gain: [[1, 1.4], [1]]}"}, "controller.baseline.gain",
            "different");
  expectKey({"controller.baseline=3"}, "controller.baseline", "a map");
  expectKey({"model.type=triple_integrator"}, "model.type", "double_integrator or linear");
  expectKey({"controller.estimator.initial_estimate=guess"},
            "controller.estimator.initial_estimate");
}

TEST(ScenarioLoader, RefusesWrongSizesAndValues) {
  expectKey({"controller.separation=[5, 0, 0]"}, "controller.separation", "2 entries");
  expectKey({"controller.baseline={gain: 1}"}, "controller.baseline.gain", "square");
  expectKey({"leader.initial_state=[5]"}, "leader.initial_state", "2 entries");
  expectKey({"follower.initial_state=[0, .nan]"}, "follower.initial_state", "non-finite");
  // Pulses are named by their path in the file (the disturbance is a list of pulses).
  expectKey({"leader.disturbance.0.vector=[1]"}, "leader.disturbance.0.vector", "2 entries");
  expectKey({"leader.disturbance.0.vector=[.nan, 0]"}, "leader.disturbance.0.vector", "non-finite");
  expectKey({"leader.disturbance.0.end=10"}, "leader.disturbance.0.end", "later");
  expectKey({"leader.disturbance.0.start=.inf"}, "leader.disturbance.0.start", "finite");
  expectKey({"leader.input={pulses: [{start: 0, end: 1, vector: [1, 2]}]}"},
            "leader.input.pulses.0.vector", "1 entries");
  expectKey({"simulation.duration=0"}, "simulation.duration", "positive");
  expectKey({"model.dimension=4"}, "model.dimension", "1, 2 or 3");
  expectKey({"controller.alpha=1.5"}, "controller.alpha", "[0, 1)");
  expectKey({"controller.epsilon=0"}, "controller.epsilon", "positive");
  expectKey({"controller.separation=[5, 1]"}, "controller.separation", "ker(A)");
  expectKey({"controller.baseline={gain: [[0, 0]]}"}, "controller.baseline.gain", "Hurwitz");
  expectKey({"controller.baseline.gain=[[1, 1.4]]"}, "controller.baseline.gain",
            "either gain or natural_frequency");
  expectKey({"controller.estimator.lyapunov_weight=[[1, 2], [2, 1]]"},
            "controller.estimator.lyapunov_weight", "positive definite");
}

TEST(ScenarioLoader, RefusesStringsForNumbersAndBooleans) {
  // Quoted (or !!str) scalars are strings in YAML, as are string ROS parameters.
  expectKey({"controller.alpha='0.2'"}, "controller.alpha", "got the string '0.2'");
  expectKey({"controller.control_rate=\"100\""}, "controller.control_rate", "string");
  expectKey({"controller.alpha=!!str 0.2"}, "controller.alpha", "string");
  expectKey({"controller.tracker.enabled='true'"}, "controller.tracker.enabled", "string");
  expectKey({"controller.estimator.substeps='2'"}, "controller.estimator.substeps", "string");
  expectKey({"controller.separation=[5, '0']"}, "controller.separation", "string");
  expectKey({"controller.tracker.gain=[[10, '5']]"}, "controller.tracker.gain.0", "string");
  expectKey({"controller.estimator.gain='-5'"}, "controller.estimator.gain", "string");
  // The same scalars unquoted are numbers and booleans; strings stay strings.
  const Scenario s =
      parseScenario(paperText(), {"controller.alpha=0.25", "model.type='double_integrator'",
                                  "controller.estimator.initial_estimate='zero'"});
  EXPECT_DOUBLE_EQ(s.controller.alpha, 0.25);
  EXPECT_EQ(s.controller.initial_estimate, InitialEstimate::kZero);
}

TEST(ScenarioLoader, AcceptsWholeNumbersWhereRealsAreExpected) {
  const Scenario s = parseScenario(
      paperText(), {"controller.alpha=0", "controller.control_rate=100", "controller.epsilon=1",
                    "controller.separation=[5, 0]", "controller.baseline={gain: [[1, 2]]}",
                    "controller.acceleration_limit=50", "simulation.duration=60",
                    "leader.disturbance=[{start: 20, end: 23, vector: [-2, -2]}]"});
  EXPECT_DOUBLE_EQ(s.controller.alpha, 0.0);
  EXPECT_DOUBLE_EQ(s.controller.control_rate, 100.0);
  EXPECT_DOUBLE_EQ(s.controller.epsilon, 1.0);
  EXPECT_DOUBLE_EQ(s.controller.acceleration_limit, 50.0);
  EXPECT_DOUBLE_EQ(s.disturbance.pulses[0].start, 20.0);
}

TEST(ScenarioLoader, RefusesWholeNumbersOutOfRange) {
  expectKey({"controller.estimator.substeps=1e12"}, "controller.estimator.substeps", "within");
  expectKey({"controller.estimator.substeps=-1e12"}, "controller.estimator.substeps", "within");
  expectKey({"controller.estimator.substeps=.nan"}, "controller.estimator.substeps", "whole");
  expectKey({"controller.estimator.substeps=.inf"}, "controller.estimator.substeps", "whole");
  expectKey({"controller.estimator.substeps=2000000000"}, "controller.estimator.substeps",
            "between 1 and 1000");
  expectKey({"model.dimension=1e10"}, "model.dimension", "whole");
  expectKey({"model.dimension=1.5"}, "model.dimension", "whole number, got '1.5'");
}

TEST(ScenarioLoader, NamesNaturalFrequencyAndDampingSeparately) {
  expectKey({"controller.baseline.damping=0"}, "controller.baseline.damping", "positive");
  expectKey({"controller.baseline.damping=.nan"}, "controller.baseline.damping", "finite");
  expectKey({"controller.baseline.natural_frequency=-1"}, "controller.baseline.natural_frequency",
            "positive");
  expectKey({"controller.baseline.damping=[0.7, 0.7]"}, "controller.baseline.damping",
            "one per axis (1), got 2");
  expectKey({"controller.baseline.natural_frequency=[1, 1]"},
            "controller.baseline.natural_frequency", "one per axis");
  expectKey({"controller.tracker={enabled: true, natural_frequency: 2, damping: -1}"},
            "controller.tracker.damping", "positive");
}

TEST(ScenarioLoader, RefusesKeysThatAreNotNames) {
  std::string text = paperText();
  text.replace(text.find("controller:\n"), 12, "controller:\n  [1, 2]: 3\n");
  try {
    parseScenario(text);
    ADD_FAILURE() << "accepted a list as a key";
  } catch (const ParameterError& error) {
    EXPECT_EQ(error.key(), "controller") << error.what();
  }
  try {
    parseScenario(paperText() + "[1]: 2\n");
    ADD_FAILURE() << "accepted a list as a key";
  } catch (const ParameterError& error) {
    EXPECT_EQ(error.key(), "(root)") << error.what();
  }
}

TEST(ScenarioLoader, RefusesBadOverridesAndFiles) {
  expectKey({"controller.alpha"}, "controller.alpha", "key=value");
  expectKey({"leader.disturbance.5.start=1"}, "leader.disturbance.5.start", "past the end");
  expectKey({"controller.alpha.value=1"}, "controller.alpha.value", "not a map");
  expectKey({"controller..alpha=1"}, "controller..alpha", "empty");
  EXPECT_THROW(loadScenarioFile("/nonexistent/scenario.yaml"), ParameterError);
  try {
    loadScenarioFile(SCENARIO_DIR);
    ADD_FAILURE() << "accepted a directory";
  } catch (const ParameterError& error) {
    EXPECT_EQ(error.key(), "(file)");
    EXPECT_NE(std::string(error.what()).find("directory"), std::string::npos) << error.what();
  }
  EXPECT_THROW(parseScenario("model: [unclosed"), ParameterError);
  EXPECT_THROW(parseScenario("- a\n- b\n"), ParameterError);
}

/// A file in the temporary directory, named after this process, removed when the test ends.
class ScratchFile {
 public:
  explicit ScratchFile(const std::string& name)
      : path_(std::filesystem::temp_directory_path() /
              ("test_scenario_loader_" + std::to_string(::getpid()) + "_" + name)) {}
  ~ScratchFile() {
    std::error_code ignored;
    std::filesystem::remove(path_, ignored);
  }
  ScratchFile(const ScratchFile&) = delete;
  ScratchFile& operator=(const ScratchFile&) = delete;
  ScratchFile(ScratchFile&&) = delete;
  ScratchFile& operator=(ScratchFile&&) = delete;

  std::string path() const { return path_.string(); }
  void write(const std::string& text) const { std::ofstream(path_, std::ios::binary) << text; }

 private:
  std::filesystem::path path_;
};

/// The message of the ParameterError that loading @p path ends with (key "(file)").
std::string fileRefusal(const std::string& path) {
  try {
    loadScenarioFile(path);
  } catch (const ParameterError& error) {
    EXPECT_EQ(error.key(), "(file)") << error.what();
    return error.what();
  }
  ADD_FAILURE() << "accepted " << path;
  return "";
}

TEST(ScenarioLoaderLimits, RefusesAFileOverTheSizeLimit) {
  // The paper's scenario padded with a comment to the limit is read; one byte more is not.
  ScratchFile file("padded.yaml");
  std::string text = paperText() + "#";
  text.resize(kMaxScenarioBytes, 'x');
  file.write(text);
  EXPECT_DOUBLE_EQ(loadScenarioFile(file.path()).controller.alpha, 0.2);
  file.write(text + "x");
  std::string message = fileRefusal(file.path());
  EXPECT_NE(message.find("'" + file.path() + "' has " + std::to_string(kMaxScenarioBytes + 1) +
                         " bytes, over the size limit of a scenario (" +
                         std::to_string(kMaxScenarioBytes) + " bytes)"),
            std::string::npos)
      << message;
}

TEST(ScenarioLoaderLimits, RefusesALargeFileByItsSizeBeforeReadingIt) {
  // 16 GiB, sparse: read, it would take that much memory.
  ScratchFile file("sparse.yaml");
  file.write("a: 1\n");
  const std::uintmax_t size = std::uintmax_t{1} << 34U;
  std::error_code error;
  std::filesystem::resize_file(file.path(), size, error);
  if (error) {
    GTEST_SKIP() << "cannot make a sparse file here: " << error.message();
  }
  const std::string message = fileRefusal(file.path());
  EXPECT_NE(message.find("has " + std::to_string(size) + " bytes"), std::string::npos) << message;
  EXPECT_NE(message.find("size limit"), std::string::npos) << message;
}

TEST(ScenarioLoaderLimits, StopsReadingAFileOfUnknownSizeAtTheLimit) {
  // A device without end: refused once one byte more than the limit has been read.
  if (!std::filesystem::exists("/dev/zero")) {
    GTEST_SKIP() << "no /dev/zero";
  }
  const std::string message = fileRefusal("/dev/zero");
  EXPECT_NE(message.find("has more than " + std::to_string(kMaxScenarioBytes) + " bytes"),
            std::string::npos)
      << message;
}

TEST(ScenarioLoader, RunsTheCallersCheckBeforeTheDesignsDerivedChecks) {
  // At 0.999 Hz one RK4 substep of the estimator is unstable: the design alone names substeps.
  const std::vector<std::string> slow = {"controller.control_rate=0.999"};
  expectKey(slow, "controller.estimator.substeps", "RK4");
  // A caller that refuses rates below 1 Hz has the rate named instead.
  ScenarioLoadOptions options;
  options.check = [](const Scenario& scenario) {
    if (scenario.controller.control_rate < 1.0) {
      throw ParameterError("controller.control_rate", "below 1 Hz");
    }
  };
  try {
    parseScenario(paperText(), slow, options);
    ADD_FAILURE() << "accepted a rate of 0.999 Hz";
  } catch (const ParameterError& error) {
    EXPECT_EQ(error.key(), "controller.control_rate") << error.what();
  }
  // The loader's own per-key checks come first: the check sees only values that passed them,
  // and runs once on a valid scenario.
  int checks = 0;
  options.check = [&checks](const Scenario&) { ++checks; };
  try {
    parseScenario(paperText(), {"simulation.duration=-1"}, options);
    ADD_FAILURE() << "accepted a negative duration";
  } catch (const ParameterError& error) {
    EXPECT_EQ(error.key(), "simulation.duration") << error.what();
  }
  EXPECT_EQ(checks, 0);
  parseScenario(paperText(), {}, options);
  EXPECT_EQ(checks, 1);
}

}  // namespace
}  // namespace projection_collision_avoidance
