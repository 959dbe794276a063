/// rostest: a formation (formation.launch) through the ROS graph on simulated time, against
/// cf_sim's figures (simulateFormation()) for the same scenario and formation. Parameters
/// (<param>s of the test node):
///   ~scenario        the scenario with its formation section, loaded as the nodes load it
///   ~end_time        simulated seconds to observe
///   ~tolerance       largest difference to cf_sim of each follower's max ||xi|| and min
///                    separation (m)
///   ~wall_deadline   wall seconds to wait for end_time
///   ~peak_ratio_limit  when > 0: each follower's max ||xi|| at most this times its target's
///                    (string stability along the chain; the leader's peak ratio is not defined)
///   ~xi_bounded      every follower's max ||xi|| within its xi_max (a string-stable setting)
///   ~first_out_of_bound  when > 0: the follower expected to be the first outside its xi_max (a
///                    chain that is not string stable): those before it stay within it, it does
///                    not, and only those before it are held outside their perimeter
///   ~min_neighbour_separation  when > 0: the smallest distance over the pairs of which neither
///                    looks at the other (the plant's odometry) at least this (m)
///   ~relative_time   (optional, default false) end_time counts from each follower's first status
///                    seen, not from time 0: for wall-time runs (test/multihost), where each
///                    follower's stamps are on its own host's clock
/// Every follower must report its own place (formation index, target), hear its target's
/// broadcast, keep ||xi_hat|| within its xi_max, and keep its target outside its perimeter by the
/// plant's odometry; the smallest distance over the pairs of which neither looks at the other
/// (the plant's odometry) must be cf_sim's within ~tolerance; with formation.neighbours every
/// follower must report a fresh neighbour array holding every other agent, none refused but the
/// sample of t = 0.

#include <cmath>
#include <cstddef>
#include <limits>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>
#include <nav_msgs/Odometry.h>
#include <ros/ros.h>

#include "projection_collision_avoidance/core/ControllerDesign.hpp"
#include "projection_collision_avoidance/core/Formation.hpp"
#include "projection_collision_avoidance/ros/ScenarioParameters.hpp"
#include "projection_collision_avoidance/sim/SampledSimulator.hpp"

#include "test_common.h"

namespace projection_collision_avoidance {
namespace {

/// What the test saw of one agent.
struct AgentRecord {
  std::string name;
  int target = 0;                ///< index into the agents (0 the leader)
  testing::StatusRecord status;  ///< followers only
  double first_time = std::numeric_limits<double>::quiet_NaN();  ///< s, first status seen
  std::map<ros::Time, Eigen::VectorXd> positions;                ///< odometry positions by stamp
};

class FormationTest : public testing::RosTestFixture {
 protected:
  FormationTest() {
    scenario_ = loadScenarioParameter(private_nh_);
    members_ = layoutFormation(scenario_.formation, scenario_.controller.separation,
                               scenario_.leader_initial_state, scenario_.follower_initial_state);
    agents_.resize(members_.size() + 1);
    agents_[0].name = "leader";
    for (std::size_t i = 0; i < members_.size(); ++i) {
      agents_[i + 1].name = members_[i].name;
      agents_[i + 1].target = members_[i].target;
    }
    for (std::size_t a = 0; a < agents_.size(); ++a) {
      subscribers_.push_back(nh_.subscribe<nav_msgs::Odometry>(
          "/" + agents_[a].name + "/odom", 1000,
          [this, a](const nav_msgs::Odometry::ConstPtr& msg) { onOdometry(a, *msg); }));
      if (a > 0) {
        subscribers_.push_back(
            nh_.subscribe<FollowerStatus>("/" + agents_[a].name + "/status", 1000,
                                          [this, a](const FollowerStatus::ConstPtr& msg) {
                                            const std::lock_guard<std::mutex> lock(mutex_);
                                            if (std::isnan(agents_[a].first_time)) {
                                              agents_[a].first_time = msg->header.stamp.toSec();
                                            }
                                            testing::addStatus(*msg, &agents_[a].status);
                                          }));
      }
    }
  }

  /// Spins until every follower has a status stamped at or after @p sim_seconds (after its first
  /// status's stamp plus @p sim_seconds when @p relative).
  bool waitForAll(double sim_seconds, double wall_seconds, bool relative) {
    return waitFor(
        [this, sim_seconds, relative] {
          for (std::size_t a = 1; a < agents_.size(); ++a) {
            const double origin = relative ? agents_[a].first_time : 0.0;
            if (std::isnan(origin) || agents_[a].status.last_time < origin + sim_seconds) {
              return false;
            }
          }
          return true;
        },
        wall_seconds);
  }

  Scenario scenario_;
  std::vector<FormationMember> members_;

  /// min ||p_target - p_i|| over the plant ticks at which both odometries arrived (m), and the
  /// number of such ticks.
  std::pair<double, int> trueMinSeparation(std::size_t a) const {
    const AgentRecord& agent = agents_[a];
    const AgentRecord& target = agents_[static_cast<std::size_t>(agent.target)];
    double smallest = std::numeric_limits<double>::infinity();
    int ticks = 0;
    for (const auto& [stamp, position] : agent.positions) {
      const auto match = target.positions.find(stamp);
      if (match != target.positions.end()) {
        smallest = std::min(smallest, (match->second - position).norm());
        ++ticks;
      }
    }
    return {smallest, ticks};
  }
  /// min ||p_a - p_b|| over the pairs of which neither looks at the other, at the plant ticks
  /// at which both odometries arrived (m; infinity: no such pair).
  double trueMinNeighbourSeparation() const {
    double smallest = std::numeric_limits<double>::infinity();
    for (std::size_t a = 0; a < agents_.size(); ++a) {
      for (std::size_t b = a + 1; b < agents_.size(); ++b) {
        if (agents_[b].target == static_cast<int>(a) || agents_[a].target == static_cast<int>(b)) {
          continue;  // leader and follower of each other: the paper's pair
        }
        for (const auto& [stamp, position] : agents_[a].positions) {
          const auto match = agents_[b].positions.find(stamp);
          if (match != agents_[b].positions.end()) {
            smallest = std::min(smallest, (match->second - position).norm());
          }
        }
      }
    }
    return smallest;
  }
  std::vector<AgentRecord> agents_;

 private:
  void onOdometry(std::size_t a, const nav_msgs::Odometry& msg) {
    const std::lock_guard<std::mutex> lock(mutex_);
    const int axes = scenario_.controller.model.double_integrator_axes;
    const Eigen::Vector3d p(msg.pose.pose.position.x, msg.pose.pose.position.y,
                            msg.pose.pose.position.z);
    agents_[a].positions[msg.header.stamp] = p.head(axes);
  }

  std::vector<ros::Subscriber> subscribers_;
};

TEST_F(FormationTest, EveryFollowerHoldsItsSlotAsCfSimDoes) {
  const double end_time = param("end_time");
  const double tolerance = param("tolerance");
  const double peak_ratio_limit = param("peak_ratio_limit");
  const int first_out_of_bound = static_cast<int>(param("first_out_of_bound"));
  bool xi_bounded = false;
  EXPECT_TRUE(private_nh_.getParam("xi_bounded", xi_bounded))
      << "missing test parameter ~xi_bounded";
  Scenario scenario = scenario_;
  scenario.duration = end_time;
  const FormationSummary expected = simulateFormation(scenario);
  bool relative_time = false;
  private_nh_.getParam("relative_time", relative_time);
  ASSERT_TRUE(waitForAll(end_time, param("wall_deadline"), relative_time))
      << "not every follower reached t = " << end_time << " s";
  const std::lock_guard<std::mutex> lock(mutex_);
  for (std::size_t i = 0; i < members_.size(); ++i) {
    const FormationMember& member = members_[i];
    const AgentRecord& agent = agents_[i + 1];
    const SimulationSummary& cf_sim = expected.followers[i];
    const ControllerDesign design =
        ControllerDesign::create(memberParameters(scenario.controller, member));
    SCOPED_TRACE(member.name + " -> " + member.target_name);
    const auto [true_min_separation, matched_ticks] = trueMinSeparation(i + 1);
    ROS_INFO(
        "%s -> %s: ROS max |xi| %.4f, max |xi_hat| %.4f, min separation %.4f (true %.4f), "
        "%d statuses; cf_sim %.4f, %.4f, %.4f",
        member.name.c_str(), member.target_name.c_str(), agent.status.max_xi,
        agent.status.max_xi_hat, agent.status.min_separation, true_min_separation,
        agent.status.count, cf_sim.max_xi, cf_sim.max_xi_hat, cf_sim.min_separation);
    // The delay of the shared information this follower saw: the link's, plus the transport.
    ROS_INFO("%s: leader_age mean %.4f s, max %.4f s over %d statuses", member.name.c_str(),
             agent.status.leader_age_count > 0
                 ? agent.status.leader_age_sum / agent.status.leader_age_count
                 : std::numeric_limits<double>::quiet_NaN(),
             agent.status.max_leader_age, agent.status.leader_age_count);
    EXPECT_EQ(agent.status.last.formation_index, static_cast<unsigned>(member.index));
    EXPECT_EQ(agent.status.last.target, member.target_name);
    EXPECT_EQ(agent.status.last.header.frame_id, member.name);
    // The target's broadcast (the leader's, or the command of the follower ahead) is heard and
    // accepted, although it carries no state in a chain.
    EXPECT_TRUE(agent.status.last.leader_fresh);
    EXPECT_NEAR(agent.status.last.xi_max, design.xi_max, 1e-12);
    EXPECT_GT(agent.status.count,
              static_cast<int>(0.5 * end_time * scenario.controller.control_rate));
    EXPECT_LE(agent.status.max_xi_hat, design.xi_max);
    EXPECT_GT(matched_ticks, static_cast<int>(0.5 * end_time * scenario.controller.control_rate));
    const bool expected_safe = first_out_of_bound <= 0 || member.index < first_out_of_bound;
    if (expected_safe) {
      EXPECT_GT(true_min_separation, design.perimeter);
    }
    if (first_out_of_bound > 0) {
      EXPECT_EQ(agent.status.max_xi <= design.xi_max, expected_safe)
          << "max |xi| " << agent.status.max_xi << ", xi_max " << design.xi_max;
    }
    if (first_out_of_bound > 0 && !expected_safe) {
      continue;  // past the first one the figures of a growing chain are not compared
    }
    EXPECT_NEAR(agent.status.max_xi, cf_sim.max_xi, tolerance);
    EXPECT_NEAR(agent.status.min_separation, cf_sim.min_separation, tolerance);
    if (xi_bounded) {
      EXPECT_LE(agent.status.max_xi, design.xi_max);
    }
    if (scenario.formation.neighbours.enabled) {  // every agent of its neighbours array kept
      EXPECT_TRUE(agent.status.last.neighbours_configured);
      EXPECT_TRUE(agent.status.last.neighbours_fresh);
      // No array of the plant is refused but, when it came after the follower subscribed, the
      // sample of t = 0 (stamp 0).
      EXPECT_LE(agent.status.last.rejected_neighbours, 1U);
      EXPECT_EQ(agent.status.last.neighbours_sent, members_.size());
    }
    if (peak_ratio_limit > 0.0 && member.target > 0) {
      const double target_peak = agents_[static_cast<std::size_t>(member.target)].status.max_xi;
      EXPECT_LE(agent.status.max_xi, peak_ratio_limit * target_peak)
          << "peak ratio " << agent.status.max_xi / target_peak;
    }
  }
  // Every pair of agents of which neither looks at the other, by the plant's odometry, as cf_sim
  // has it: without formation.neighbours unprotected, with it kept apart.
  const double neighbour_separation = trueMinNeighbourSeparation();
  ROS_INFO("neighbour pairs: ROS min separation %.4f, cf_sim %.4f (rho %.4f)", neighbour_separation,
           expected.min_neighbour_separation, expected.perimeter);
  if (std::isfinite(expected.min_neighbour_separation) && first_out_of_bound <= 0) {
    EXPECT_NEAR(neighbour_separation, expected.min_neighbour_separation, tolerance);
  }
  const double min_neighbour_separation = param("min_neighbour_separation");
  if (min_neighbour_separation > 0.0) {
    EXPECT_GE(neighbour_separation, min_neighbour_separation);
  }
}

}  // namespace
}  // namespace projection_collision_avoidance
