/// The cf_sim command: exit codes, the summary line and the CSV.

#include <cstdio>
#include <fstream>
#include <map>
#include <sstream>

#include <gtest/gtest.h>

#include "projection_collision_avoidance/scenario/CfSimApp.hpp"

#include "TestScenarios.hpp"

namespace projection_collision_avoidance {
namespace {

using testing::scenarioPath;

struct Result {
  int code;
  std::string out;
  std::string err;
};

Result runApp(const std::vector<std::string>& arguments) {
  std::ostringstream out;
  std::ostringstream err;
  const int code = runCfSim(arguments, out, err);
  return {code, out.str(), err.str()};
}

std::map<std::string, double> parseSummary(const std::string& line) {
  std::map<std::string, double> values;
  std::istringstream stream(line);
  for (std::string pair; stream >> pair;) {
    const std::size_t equals = pair.find('=');
    values[pair.substr(0, equals)] = std::stod(pair.substr(equals + 1));
  }
  return values;
}

TEST(CfSim, PrintsTheSummaryLine) {
  const Result run1 = runApp({scenarioPath("paper_run1.yaml")});
  ASSERT_EQ(run1.code, 0) << run1.err;
  const auto values = parseSummary(run1.out);
  for (const char* key :
       {"max_xi", "max_xi_hat", "xi_max", "min_separation", "time_outside", "wall_s"}) {
    EXPECT_EQ(values.count(key), 1u) << key << " missing from: " << run1.out;
  }
  EXPECT_GT(values.at("max_xi"), values.at("xi_max"));
  EXPECT_LE(values.at("max_xi_hat"), values.at("xi_max"));
  EXPECT_GT(values.at("time_outside"), 0.0);
  const Result run2 = runApp({scenarioPath("paper_run2.yaml"), "--set", "controller.alpha=0.1"});
  ASSERT_EQ(run2.code, 0) << run2.err;
  EXPECT_DOUBLE_EQ(parseSummary(run2.out).at("xi_max"), 4.5);
  EXPECT_EQ(parseSummary(run2.out).at("time_outside"), 0.0);
}

TEST(CfSim, WritesTheCsv) {
  const std::string path = ::testing::TempDir() + "cf_sim_test.csv";
  const Result result =
      runApp({scenarioPath("paper_run2.yaml"), "--csv", path, "--set", "simulation.duration=1.0"});
  ASSERT_EQ(result.code, 0) << result.err;
  std::ifstream csv(path);
  std::string header;
  std::getline(csv, header);
  EXPECT_EQ(header,
            "t,xi_0,xi_1,xi_hat_0,xi_hat_1,norm_xi,norm_xi_hat,xi_max,xi_soft,f,"
            "projection_active,leader_p_0,follower_p_0,leader_v_0,follower_v_0,separation,"
            "perimeter,u_0,u_baseline_0,u_tracker_0,leader_u_0,ud_0,ud_1");
  int rows = 0;
  std::string row;
  std::string first;
  while (std::getline(csv, row)) {
    if (rows == 0) {
      first = row;
    }
    ++rows;
  }
  EXPECT_EQ(rows, 1001);  // t = 0, 0.001, ..., 1.0
  EXPECT_EQ(first.rfind("0,0,0,0,0,0,0,4,", 0), 0u) << first;
  std::remove(path.c_str());
}

TEST(CfSim, BadScenariosExitNonZeroNamingTheKey) {
  const Result unknown = runApp({scenarioPath("paper_run2.yaml"), "--set", "controller.alfa=0.2"});
  EXPECT_EQ(unknown.code, 1);
  EXPECT_NE(unknown.err.find("controller.alfa: unknown key"), std::string::npos) << unknown.err;
  EXPECT_TRUE(unknown.out.empty());
  const Result range = runApp({scenarioPath("paper_run2.yaml"), "--set", "controller.alpha=-1"});
  EXPECT_EQ(range.code, 1);
  EXPECT_NE(range.err.find("controller.alpha"), std::string::npos) << range.err;
  const Result missing = runApp({"/nonexistent.yaml"});
  EXPECT_EQ(missing.code, 1);
}

TEST(CfSim, ChoosesTheContinuousMethod) {
  const std::string scenario = scenarioPath("paper_run2.yaml");
  const Result rk4 = runApp({scenario, "--continuous", "0.005"});
  const Result rk6 = runApp({scenario, "--continuous", "0.02", "--method", "rk6"});
  const Result rk4_named = runApp({scenario, "--continuous", "0.005", "--method", "rk4"});
  ASSERT_EQ(rk4.code, 0) << rk4.err;
  ASSERT_EQ(rk6.code, 0) << rk6.err;
  ASSERT_EQ(rk4_named.code, 0) << rk4_named.err;
  const auto a = parseSummary(rk4.out);
  const auto b = parseSummary(rk6.out);
  EXPECT_EQ(a.at("max_xi"), parseSummary(rk4_named.out).at("max_xi"));  // rk4 is the default
  // Two methods at different steps, one model: the summaries agree to their print precision.
  EXPECT_NEAR(a.at("max_xi"), b.at("max_xi"), 1e-7);
  EXPECT_NEAR(a.at("min_separation"), b.at("min_separation"), 1e-7);
  EXPECT_EQ(runApp({scenario, "--method", "rk6"}).code, 2);  // needs --continuous
  const Result unknown = runApp({scenario, "--continuous", "0.01", "--method", "euler"});
  EXPECT_EQ(unknown.code, 2);
  EXPECT_NE(unknown.err.find("rk4 or rk6"), std::string::npos) << unknown.err;
}

// The sampled run honours controller.jerk_limit; the continuous-time law has no period to
// limit the change over and refuses it, naming the key, rather than ignoring it.
TEST(CfSim, JerkLimitInSampledRunsRefusedInContinuousOnes) {
  const std::string scenario = scenarioPath("paper_run2.yaml");
  const Result free_run = runApp({scenario});
  const Result limited = runApp({scenario, "--set", "controller.jerk_limit=10"});
  ASSERT_EQ(free_run.code, 0) << free_run.err;
  ASSERT_EQ(limited.code, 0) << limited.err;
  const auto free_values = parseSummary(free_run.out);
  const auto limited_values = parseSummary(limited.out);
  // The slower command lets the disturbance push further, still inside the bound.
  EXPECT_GT(limited_values.at("max_xi"), free_values.at("max_xi"));
  EXPECT_LT(limited_values.at("min_separation"), free_values.at("min_separation"));
  EXPECT_LT(limited_values.at("max_xi"), limited_values.at("xi_max"));
  const Result continuous =
      runApp({scenario, "--set", "controller.jerk_limit=2", "--continuous", "0.01"});
  EXPECT_EQ(continuous.code, 2);
  EXPECT_NE(continuous.err.find("controller.jerk_limit"), std::string::npos) << continuous.err;
  EXPECT_TRUE(continuous.out.empty());
  const Result no_limit =
      runApp({scenario, "--set", "controller.jerk_limit=.inf", "--continuous", "0.01"});
  EXPECT_EQ(no_limit.code, 0) << no_limit.err;
}

TEST(CfSim, UsageErrorsExitWithTwo) {
  EXPECT_EQ(runApp({}).code, 2);
  EXPECT_EQ(runApp({scenarioPath("paper_run2.yaml"), "--set"}).code, 2);
  EXPECT_EQ(runApp({scenarioPath("paper_run2.yaml"), "--frobnicate"}).code, 2);
  EXPECT_EQ(runApp({"a.yaml", "b.yaml"}).code, 2);
  EXPECT_EQ(runApp({scenarioPath("paper_run2.yaml"), "--csv", "/nonexistent/dir/x.csv"}).code, 3);
}

}  // namespace
}  // namespace projection_collision_avoidance
