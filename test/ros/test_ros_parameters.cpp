/// The nodes' reading of a scenario without a master (src/ros/RosParameters.cpp): their own
/// requirements run before the controller design's derived checks, and the XmlRpc -> YAML
/// conversion keeps the depth and node limits of scenario files.

#include <cstddef>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <xmlrpcpp/XmlRpcValue.h>

#include "projection_collision_avoidance/configuration/ConfigurationLoader.hpp"
#include "projection_collision_avoidance/core/ParameterError.hpp"
#include "projection_collision_avoidance/ros/RosParameters.hpp"
#include "projection_collision_avoidance/scenario/ScenarioLoader.hpp"

namespace projection_collision_avoidance {
namespace {

std::string paperText() {
  std::ifstream file(std::string(SCENARIO_DIR) + "/paper_run2.yaml");
  std::stringstream text;
  text << file.rdbuf();
  return text.str();
}

ScenarioLoadOptions nodeScenarioOptions() {
  ScenarioLoadOptions options;
  options.check = [](const Scenario& scenario) { requireNodeController(scenario.controller); };
  return options;
}

ConfigurationLoadOptions nodeConfigurationOptions() {
  ConfigurationLoadOptions options;
  options.check = [](const FollowerConfiguration& configuration) {
    requireNodeController(configuration.controller);
  };
  return options;
}

/// The ParameterError of loading the paper's Run 2 with @p overrides under the nodes' checks, as
/// the simulation nodes load it (the whole scenario) and as a follower does (its configuration):
/// the two name the same key, which is returned.
ParameterError nodeRefusal(const std::vector<std::string>& overrides) {
  ParameterError scenario_error("", "");
  try {
    parseScenario(paperText(), overrides, nodeScenarioOptions());
    ADD_FAILURE() << "the scenario was accepted";
  } catch (const ParameterError& error) {
    scenario_error = error;
  }
  try {
    parseFollowerConfiguration(paperText(), overrides, nodeConfigurationOptions());
    ADD_FAILURE() << "the follower's configuration was accepted";
  } catch (const ParameterError& error) {
    EXPECT_EQ(error.key(), scenario_error.key()) << error.what();
    EXPECT_EQ(error.reason(), scenario_error.reason()) << error.what();
  }
  return scenario_error;
}

TEST(NodeScenario, NamesTheControlRateTheUserWrote) {
  // Without the nodes' check the design names estimator.substeps (RK4 unstable at T = 1.001 s).
  for (const double rate : {0.999, kMinNodeRate / 2.0, kMaxNodeRate * 2.0}) {
    const ParameterError error = nodeRefusal({"controller.control_rate=" + std::to_string(rate)});
    EXPECT_EQ(error.key(), "controller.control_rate") << error.what();
    EXPECT_NE(error.reason().find("the ROS nodes run at"), std::string::npos) << error.what();
  }
  for (const double rate : {kMinNodeRate * 100.0, kMaxNodeRate}) {
    const std::vector<std::string> overrides{"controller.control_rate=" + std::to_string(rate)};
    EXPECT_NO_THROW(parseScenario(paperText(), overrides, nodeScenarioOptions()));
    EXPECT_NO_THROW(parseFollowerConfiguration(paperText(), overrides, nodeConfigurationOptions()));
  }
}

TEST(NodeScenario, NamesTheModelTypeBeforeTheGainsOfALinearModel) {
  // A linear model whose baseline gain is not stabilising: the nodes refuse the model first.
  const ParameterError error = nodeRefusal(
      {"model={type: linear, A: [[0, 1], [0, 0]], B: [[0], [1]], position_dimension: 1}",
       "controller.baseline={gain: [[-1, 1.4]]}"});
  EXPECT_EQ(error.key(), "model.type") << error.what();
  EXPECT_NE(error.reason().find("double_integrator"), std::string::npos) << error.what();
}

/// @p depth arrays nested in one another below the key "extra" of a struct, with a 1 inside.
XmlRpc::XmlRpcValue nestedArrays(std::size_t depth) {
  XmlRpc::XmlRpcValue root;
  XmlRpc::XmlRpcValue* inner = &root["extra"];
  for (std::size_t level = 0; level < depth; ++level) {
    inner->setSize(1);
    inner = &(*inner)[0];
  }
  *inner = 1;
  return root;
}

TEST(ToYaml, RefusesNestingOverTheDepthLimit) {
  // The struct is the first level.
  EXPECT_TRUE(toYaml(nestedArrays(kMaxScenarioDepth - 1))["extra"].IsSequence());
  try {
    toYaml(nestedArrays(kMaxScenarioDepth));
    ADD_FAILURE() << "accepted " << kMaxScenarioDepth + 1 << " levels";
  } catch (const ParameterError& error) {
    std::string key = "extra";
    for (std::size_t level = 1; level < kMaxScenarioDepth; ++level) {
      key += ".0";
    }
    EXPECT_EQ(error.key(), key);
    EXPECT_NE(error.reason().find("depth limit of a scenario (" +
                                  std::to_string(kMaxScenarioDepth) + " lists and maps)"),
              std::string::npos)
        << error.what();
  }
}

TEST(ToYaml, RefusesTreesOverTheNodeLimit) {
  XmlRpc::XmlRpcValue list;
  list.setSize(static_cast<int>(kMaxScenarioNodes - 1));
  // NOLINTNEXTLINE(modernize-loop-convert): XmlRpcValue's iterators walk a struct, not an array
  for (int i = 0; i < list.size(); ++i) {
    list[i] = 1;
  }
  EXPECT_EQ(toYaml(list).size(), kMaxScenarioNodes - 1);
  list.setSize(static_cast<int>(kMaxScenarioNodes));
  list[list.size() - 1] = 1;
  try {
    toYaml(list);
    ADD_FAILURE() << "accepted " << kMaxScenarioNodes + 1 << " nodes";
  } catch (const ParameterError& error) {
    EXPECT_EQ(error.key(), std::to_string(kMaxScenarioNodes - 1));
    EXPECT_NE(error.reason().find("node limit of a scenario (" + std::to_string(kMaxScenarioNodes) +
                                  " nodes)"),
              std::string::npos)
        << error.what();
  }
}

}  // namespace
}  // namespace projection_collision_avoidance
