/// The link of shared information (SharedLink, (L1)-(L3)): delay, latency, losses and hold; the
/// keys of the link, the time headway and the shaped feed-forward; and that with these options
/// off the runs are those of before, bit for bit (no roscore).

#include <cmath>
#include <cstdint>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>
#include <gtest/gtest.h>

#include "projection_collision_avoidance/core/ParameterError.hpp"
#include "projection_collision_avoidance/scenario/CfSimApp.hpp"
#include "projection_collision_avoidance/scenario/ScenarioLoader.hpp"
#include "projection_collision_avoidance/sim/SampledSimulator.hpp"
#include "projection_collision_avoidance/sim/SharedLink.hpp"

#include "TestScenarios.hpp"

namespace projection_collision_avoidance {
namespace {

using testing::scenarioPath;
using Value = Eigen::Matrix<double, 1, 1>;

Value value(double x) { return Value::Constant(x); }

std::string keyOfError(const std::vector<std::string>& overrides,
                       const std::string& file = "paper_run2.yaml") {
  try {
    loadScenarioFile(scenarioPath(file), overrides);
  } catch (const ParameterError& error) {
    return error.key();
  }
  return "";
}

TEST(SharedLink, SplitMix64IsTheReferenceGenerator) {
  // The first three outputs of Vigna's splitmix64 seeded with 0 (state advanced by the golden
  // gamma before each output), so that another implementation can reproduce the losses.
  EXPECT_EQ(splitMix64(0), 0xE220A8397B1DCDAFULL);
  EXPECT_EQ(splitMix64(0x9E3779B97F4A7C15ULL), 0x6E789E6AA1B965F4ULL);
  EXPECT_EQ(splitMix64(0x3C6EF372FE94F82AULL), 0x06C45D188009454FULL);
}

TEST(SharedLink, DelaysByExactlyTheTotalPeriods) {
  for (const int delay : {0, 1, 3, 17}) {
    LinkSpec spec;
    spec.configured = true;
    spec.delay_periods = delay;
    SharedLink<Value> link(spec, 100.0, 2, 2, value(0.0));
    ASSERT_EQ(link.delay(), delay);
    for (long tick = 0; tick < 60; ++tick) {
      link.send(0, tick, value(static_cast<double>(tick) + 1.0));
      const double expected = tick >= delay ? static_cast<double>(tick - delay) + 1.0 : 0.0;
      EXPECT_EQ(link.receive(1, 0, tick)(0), expected) << "delay " << delay << " tick " << tick;
    }
  }
}

TEST(SharedLink, LatencyRoundsUpToWholePeriods) {
  LinkSpec spec;
  spec.latency = 0.02;
  EXPECT_EQ(spec.totalDelayPeriods(100.0), 2);  // arrives on a tick: read there
  EXPECT_EQ(spec.totalDelayPeriods(1000.0), 20);
  spec.latency = 0.1;
  EXPECT_EQ(spec.totalDelayPeriods(100.0), 10);
  EXPECT_EQ(spec.totalDelayPeriods(1000.0), 100);
  spec.latency = 0.0201;  // arrives after tick 2: read at tick 3
  EXPECT_EQ(spec.totalDelayPeriods(100.0), 3);
  spec.latency = 0.0004;
  EXPECT_EQ(spec.totalDelayPeriods(1000.0), 1);
  spec.delay_periods = 2;  // periods and latency add
  EXPECT_EQ(spec.totalDelayPeriods(1000.0), 3);
  spec.latency = 0.0;
  EXPECT_EQ(spec.totalDelayPeriods(1000.0), 2);
}

TEST(SharedLink, LossesFollowTheSeedAtTheirRate) {
  const long ticks = 200000;
  const double dropout = 0.2;
  long lost = 0;
  long differ_seed = 0;
  long differ_receiver = 0;
  for (long tick = 0; tick < ticks; ++tick) {
    const bool a = linkMessageLost(7, 1, tick, dropout);
    EXPECT_EQ(a, linkMessageLost(7, 1, tick, dropout));  // a function of its arguments
    lost += a ? 1 : 0;
    differ_seed += a != linkMessageLost(8, 1, tick, dropout) ? 1 : 0;
    differ_receiver += a != linkMessageLost(7, 2, tick, dropout) ? 1 : 0;
  }
  // Binomial: sigma = sqrt(p (1 - p) / n) = 0.0009; 6 sigma.
  EXPECT_NEAR(static_cast<double>(lost) / ticks, dropout, 0.0054);
  // Independent patterns disagree on 2 p (1 - p) = 32 % of the ticks.
  EXPECT_NEAR(static_cast<double>(differ_seed) / ticks, 0.32, 0.01);
  EXPECT_NEAR(static_cast<double>(differ_receiver) / ticks, 0.32, 0.01);
  EXPECT_FALSE(linkMessageLost(7, 1, 5, 0.0));
}

TEST(SharedLink, HoldsTheLastDeliveredValue) {
  LinkSpec spec;
  spec.configured = true;
  spec.delay_periods = 2;
  spec.dropout = 0.5;
  spec.seed = 42;
  SharedLink<Value> link(spec, 100.0, 3, 3, value(0.0));
  long holds = 0;
  for (long tick = 0; tick < 2000; ++tick) {
    link.send(2, tick, value(std::sin(0.1 * static_cast<double>(tick)) + 2.0));
    // Reference: the newest message sent at j <= tick - 2 that was not lost, else 0.
    double expected = 0.0;
    for (long j = tick - 2; j >= 0; --j) {
      if (!linkMessageLost(42, 1, j, 0.5)) {
        expected = std::sin(0.1 * static_cast<double>(j)) + 2.0;
        break;
      }
    }
    holds += tick >= 2 && linkMessageLost(42, 1, tick - 2, 0.5) ? 1 : 0;
    EXPECT_EQ(link.receive(1, 2, tick)(0), expected) << tick;
  }
  EXPECT_GT(holds, 800);  // the reference really held values over losses
}

TEST(SharedLink, VerdictsOnStampedMessagesReproduceTheSampledLink) {
  // A process that gets each message with its stamp (the ROS link_relay) and releases it at
  // verdict.release, unless lost, delivers at tick k what SharedLink::receive() holds at k.
  LinkSpec spec;
  spec.configured = true;
  spec.delay_periods = 1;
  spec.latency = 0.1;
  spec.dropout = 0.2;
  spec.seed = 9;
  const double rate = 100.0;
  SharedLink<Value> link(spec, rate, 2, 4, value(0.0));
  std::vector<std::pair<double, double>> in_flight;  // (release, value)
  double held = 0.0;
  long lost = 0;
  for (long tick = 0; tick < 3000; ++tick) {
    const double now = static_cast<double>(tick) / rate;
    const double sent = std::cos(0.05 * static_cast<double>(tick));
    link.send(0, tick, value(sent));
    const LinkVerdict verdict = judgeLinkMessage(spec, rate, 3, now);
    ASSERT_EQ(verdict.tick, tick);
    lost += verdict.lost ? 1 : 0;
    if (!verdict.lost) {
      in_flight.emplace_back(verdict.release, sent);
    }
    while (!in_flight.empty() && in_flight.front().first <= now + 1e-9 / rate) {
      held = in_flight.front().second;
      in_flight.erase(in_flight.begin());
    }
    ASSERT_EQ(link.receive(3, 0, tick)(0), held) << "tick " << tick;
  }
  EXPECT_GT(lost, 450);  // 20 % of 3000: the losses were exercised
  EXPECT_EQ(judgeLinkMessage(spec, rate, 3, -1.0).tick, 0);
  EXPECT_EQ(judgeLinkMessage(spec, rate, 3, std::nan("")).tick, 0);
}

TEST(LinkKeys, AreReadAndRefusedNamingTheKey) {
  const std::string link = "controller.leader_information.link";
  const std::vector<std::string> shared = {"controller.leader_information.command=true"};
  const auto with = [&shared](const std::string& assignment) {
    std::vector<std::string> overrides = shared;
    overrides.push_back(assignment);
    return overrides;
  };
  const Scenario scenario =
      loadScenarioFile(scenarioPath("paper_run2.yaml"),
                       with(link + "={delay_periods: 3, latency: 0.02, dropout: 0.1, seed: 9}"));
  EXPECT_TRUE(scenario.link.configured);
  EXPECT_EQ(scenario.link.delay_periods, 3);
  EXPECT_DOUBLE_EQ(scenario.link.latency, 0.02);
  EXPECT_DOUBLE_EQ(scenario.link.dropout, 0.1);
  EXPECT_EQ(scenario.link.seed, 9u);
  EXPECT_EQ(scenario.link.totalDelayPeriods(scenario.controller.control_rate), 23);
  EXPECT_FALSE(loadScenarioFile(scenarioPath("paper_run2.yaml")).link.configured);

  EXPECT_EQ(keyOfError(with(link + ".delay_periods=-1")), link + ".delay_periods");
  EXPECT_EQ(keyOfError(with(link + ".delay_periods=1.5")), link + ".delay_periods");
  EXPECT_EQ(keyOfError(with(link + ".delay_periods=10001")), link + ".delay_periods");
  EXPECT_EQ(keyOfError(with(link + ".latency=-0.01")), link + ".latency");
  EXPECT_EQ(keyOfError(with(link + ".latency=.nan")), link + ".latency");
  EXPECT_EQ(keyOfError(with(link + ".latency=61")), link + ".latency");
  EXPECT_EQ(keyOfError(with(link + ".latency=11")), link + ".latency");  // 11000 periods
  EXPECT_EQ(keyOfError(with(link + ".latency=[0.1]")), link + ".latency");
  EXPECT_EQ(keyOfError(with(link + ".dropout=1.0")), link + ".dropout");
  EXPECT_EQ(keyOfError(with(link + ".dropout=-0.1")), link + ".dropout");
  EXPECT_EQ(keyOfError(with(link + ".seed=-1")), link + ".seed");
  EXPECT_EQ(keyOfError(with(link + ".seed=0.5")), link + ".seed");
  EXPECT_EQ(keyOfError(with(link + ".jitter=0.1")), link + ".jitter");
  EXPECT_EQ(keyOfError(with(link + "=3")), link);
  // A link that carries nothing, and memory beyond the limit.
  EXPECT_EQ(keyOfError({link + ".latency=0.1"}), link);
  EXPECT_EQ(keyOfError(with(link + ".delay_periods=10000")), "");
  // 3 axes: 1001 agents x 10001 values x 3 entries in flight, over the limit of 2^24.
  std::vector<std::string> large = with(link + ".delay_periods=10000");
  large.push_back("formation.followers=1000");
  EXPECT_EQ(keyOfError(large, "figure_eight_3d.yaml"), link + ".delay_periods");
  large.back() = "formation.followers=500";
  EXPECT_EQ(keyOfError(large, "figure_eight_3d.yaml"), "");
}

TEST(PlatoonKeys, AreReadAndRefusedNamingTheKey) {
  const std::string ff = "controller.leader_information.feedforward";
  const std::string command = "controller.leader_information.command=true";
  const Scenario scenario = loadScenarioFile(
      scenarioPath("paper_run2.yaml"),
      {command, "controller.spacing.time_headway=0.3", ff + "={gain: 0.7, time_constant: 0.2}"});
  EXPECT_DOUBLE_EQ(scenario.controller.time_headway, 0.3);
  EXPECT_DOUBLE_EQ(scenario.controller.feedforward_gain, 0.7);
  EXPECT_DOUBLE_EQ(scenario.controller.feedforward_time_constant, 0.2);

  const std::string headway = "controller.spacing.time_headway";
  EXPECT_EQ(keyOfError({headway + "=-0.1"}), headway);
  EXPECT_EQ(keyOfError({headway + "=.inf"}), headway);
  EXPECT_EQ(keyOfError({headway + "=101"}), headway);
  EXPECT_EQ(keyOfError({"controller.spacing.gap=1"}), "controller.spacing.gap");
  EXPECT_EQ(keyOfError({"model={type: linear, A: [[0, 1], [0, 0]], B: [[0], [1]], "
                        "position_dimension: 1}",
                        "controller.baseline={gain: [[1.0, 1.4]]}", headway + "=0.3"}),
            headway);
  EXPECT_EQ(keyOfError({command, ff + ".gain=1.5"}), ff + ".gain");
  EXPECT_EQ(keyOfError({command, ff + ".gain=-0.1"}), ff + ".gain");
  EXPECT_EQ(keyOfError({command, ff + ".time_constant=-1"}), ff + ".time_constant");
  EXPECT_EQ(keyOfError({command, ff + ".time_constant=.nan"}), ff + ".time_constant");
  EXPECT_EQ(keyOfError({command, ff + ".order=2"}), ff + ".order");
  // Shaping needs something to shape.
  EXPECT_EQ(keyOfError({ff + ".gain=0.7"}), ff);
  EXPECT_EQ(keyOfError({"controller.leader_information.estimator=true", ff + ".gain=0.7"}), ff);
}

TEST(PlatoonKeys, ContinuousRefusesWhatOnlyTheSampledLoopModels) {
  const std::string command = "controller.leader_information.command=true";
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"controller.spacing.time_headway=0.3", "controller.spacing.time_headway"},
      {"controller.leader_information.feedforward.gain=0.7",
       "controller.leader_information.feedforward.gain"},
      {"controller.leader_information.feedforward.time_constant=0.2",
       "controller.leader_information.feedforward.time_constant"},
      {"controller.leader_information.link.delay_periods=2",
       "controller.leader_information.link.delay_periods"},
      {"controller.leader_information.link.latency=0.01",
       "controller.leader_information.link.latency"},
      {"controller.leader_information.link.dropout=0.2",
       "controller.leader_information.link.dropout"}};
  for (const auto& [assignment, key] : cases) {
    std::ostringstream out;
    std::ostringstream err;
    const int code = runCfSim({scenarioPath("paper_run2.yaml"), "--set", command, "--set",
                               assignment, "--continuous", "0.01"},
                              out, err);
    EXPECT_EQ(code, 2) << assignment;
    EXPECT_NE(err.str().find(key), std::string::npos) << err.str();
    EXPECT_TRUE(out.str().empty()) << out.str();
  }
  // A link that neither delays nor loses is the continuous loop's instantaneous sharing.
  std::ostringstream out;
  std::ostringstream err;
  EXPECT_EQ(runCfSim({scenarioPath("paper_run2.yaml"), "--set", command, "--set",
                      "controller.leader_information.link={seed: 3}", "--continuous", "0.01"},
                     out, err),
            0)
      << err.str();
}

/// Every sample of every follower, for bit-for-bit comparisons.
struct Trace {
  std::vector<double> values;
  FormationSummary summary;
};

Trace trace(const std::string& file, const std::vector<std::string>& overrides) {
  Trace result;
  result.summary = simulateFormation(loadScenarioFile(scenarioPath(file), overrides),
                                     [&result](int member, const SimulationSample& s) {
                                       result.values.push_back(member);
                                       const auto append = [&result](const auto& v) {
                                         result.values.insert(result.values.end(), v.data(),
                                                              v.data() + v.size());
                                       };
                                       append(s.relative_error);
                                       append(s.controller.estimate);
                                       append(s.controller.command);
                                       append(s.controller.tracker_command);
                                       append(s.follower_state);
                                     });
  return result;
}

void expectIdentical(const Trace& a, const Trace& b) {
  ASSERT_EQ(a.values.size(), b.values.size());
  std::size_t differing = 0;
  for (std::size_t i = 0; i < a.values.size(); ++i) {
    differing += a.values[i] != b.values[i] ? 1 : 0;  // bit for bit: no tolerance
  }
  EXPECT_EQ(differing, 0u);
  ASSERT_EQ(a.summary.followers.size(), b.summary.followers.size());
  for (std::size_t i = 0; i < a.summary.followers.size(); ++i) {
    EXPECT_EQ(a.summary.followers[i].max_xi, b.summary.followers[i].max_xi);
    EXPECT_EQ(a.summary.followers[i].min_separation, b.summary.followers[i].min_separation);
  }
  EXPECT_EQ(a.summary.min_pair_separation, b.summary.min_pair_separation);
}

TEST(OptionsOff, ThePaperRunsAreUnchangedBitForBit) {
  // The new keys at their off values go through the new code paths and must change nothing.
  const std::vector<std::string> off = {
      "controller.spacing.time_headway=0", "controller.leader_information.feedforward.gain=1",
      "controller.leader_information.feedforward.time_constant=0"};
  for (const char* file : {"paper_run1.yaml", "paper_run2.yaml"}) {
    for (const char* rate : {"controller.control_rate=1000", "controller.control_rate=100"}) {
      std::vector<std::string> with_off = off;
      with_off.push_back(rate);
      const Trace plain = trace(file, {rate});
      const Trace explicit_off = trace(file, with_off);
      expectIdentical(plain, explicit_off);
      // And with the leader's acceleration shared: same tick = a link without delay or loss.
      std::vector<std::string> shared = {rate, "controller.leader_information.command=true",
                                         "controller.leader_information.disturbance=true"};
      std::vector<std::string> shared_off = shared;
      shared_off.insert(shared_off.end(), off.begin(), off.end());
      shared_off.push_back("controller.leader_information.link={delay_periods: 0, seed: 4}");
      expectIdentical(trace(file, shared), trace(file, shared_off));
      EXPECT_GT(plain.values.size(), 1000u);
    }
  }
}

TEST(OptionsOff, AFormationWithAnIdealLinkIsTheSameTickChain) {
  const std::vector<std::string> chain = {
      "controller.control_rate=100", "formation.followers=8", "formation.topology=chain",
      "controller.leader_information.command=true", "controller.leader_information.estimator=true"};
  std::vector<std::string> ideal = chain;
  ideal.push_back(
      "controller.leader_information.link={delay_periods: 0, latency: 0, "
      "dropout: 0}");
  const Trace same_tick = trace("paper_run2.yaml", chain);
  expectIdentical(same_tick, trace("paper_run2.yaml", ideal));
  // A period of delay changes the run: the link is in the loop.
  std::vector<std::string> late = chain;
  late.push_back("controller.leader_information.link.delay_periods=1");
  const Trace delayed = trace("paper_run2.yaml", late);
  EXPECT_GT(delayed.summary.followers.back().max_xi,
            same_tick.summary.followers.back().max_xi + 1e-6);
}

TEST(LinkInTheLoop, TheSameSeedGivesTheSameRun) {
  const auto run = [](int seed) {
    return trace("platoon_run2.yaml",
                 {"formation.followers=10", "simulation.duration=30",
                  "controller.leader_information.link.seed=" + std::to_string(seed)});
  };
  const Trace a = run(3);
  expectIdentical(a, run(3));
  const Trace b = run(4);
  ASSERT_EQ(a.values.size(), b.values.size());
  EXPECT_NE(a.values, b.values);  // other losses, another run
}

}  // namespace
}  // namespace projection_collision_avoidance
