/// rostests of faults on a leader-follower pair (launch/pair.launch on simulated time): sensor
/// noise, dropout and latency, a measurement outage, the leader node killed, the follower node
/// killed and respawned. Each .test file selects one TEST_F with --gtest_filter and sets its
/// <param>s:
///   ~scenario          the scenario, as the nodes load it (acceleration_limit included)
///   ~end_time          simulated seconds to observe
///   ~wall_deadline     wall seconds to wait for end_time
///   ~max_xi_bound      (optional) the true ||xi|| must stay at or below this (m)
///   ~outage_start, ~outage_duration   the plant's measurement outage (s), FallbackAcrossAnOutage
///   ~kill_time         simulated second at which a node is killed, LeaderKilled / FollowerRespawn
/// Always checked: the true separation (from the plant's odometry) stays outside the safety
/// perimeter, ||xi_hat|| <= xi_max, and every command is finite and within the acceleration
/// limit.

#include <deque>
#include <utility>

#include <geometry_msgs/AccelStamped.h>
#include <gtest/gtest.h>
#include <nav_msgs/Odometry.h>
#include <ros/master.h>
#include <ros/network.h>
#include <ros/ros.h>
#include <xmlrpcpp/XmlRpc.h>

#include "projection_collision_avoidance/core/ControllerDesign.hpp"
#include "projection_collision_avoidance/ros/MessageConversions.hpp"
#include "projection_collision_avoidance/ros/ScenarioParameters.hpp"

#include "test_common.h"

namespace projection_collision_avoidance {
namespace {

/// The follower test fixture plus the plant's ground truth: true relative error and separation
/// from the two odometry streams, and the command the plant applied at each tick.
class FaultTest : public testing::FollowerTest {
 protected:
  FaultTest()
      : scenario_(loadScenarioParameter(private_nh_)),
        design_(ControllerDesign::create(scenario_.controller)),
        axes_(scenario_.controller.model.double_integrator_axes) {
    leader_subscriber_ = nh_.subscribe("/leader/odom", 1000, &FaultTest::onLeaderOdom, this);
    follower_subscriber_ = nh_.subscribe("/follower/odom", 1000, &FaultTest::onFollowerOdom, this);
    applied_subscriber_ =
        nh_.subscribe("/follower/applied_command", 1000, &FaultTest::onAppliedCommand, this);
  }

  /// Checks that hold whatever the fault, after observing up to ~end_time.
  void expectSafeRun() {
    ASSERT_TRUE(waitForStatusTime(param("end_time"), param("wall_deadline")))
        << "no status at t >= " << param("end_time") << " s; last " << record().last_time << " s";
    const testing::StatusRecord r = record();
    const std::lock_guard<std::mutex> lock(mutex_);
    ROS_INFO(
        "true max |xi| %.4f m, true min separation %.4f m (perimeter %.4f), max |xi_hat| %.4f, "
        "max |u_2| %.4f, applied-command largest jump %.4f m/s^2, %d statuses, %d fallback ticks",
        true_max_xi_, true_min_separation_, design_.perimeter, r.max_xi_hat, r.max_command,
        max_applied_jump_, r.count, r.fallback_ticks);
    EXPECT_GT(truth_samples_, 0);
    EXPECT_GT(true_min_separation_, design_.perimeter);
    EXPECT_LE(r.max_xi_hat, design_.xi_max);
    EXPECT_TRUE(r.commands_finite);
    EXPECT_TRUE(applied_finite_);
    const double limit = scenario_.controller.acceleration_limit;
    if (std::isfinite(limit)) {
      EXPECT_LE(r.max_command, limit * (1.0 + 1e-9));
    }
    double max_xi_bound = 0.0;
    if (private_nh_.getParam("max_xi_bound", max_xi_bound)) {
      EXPECT_LE(true_max_xi_, max_xi_bound);
    }
  }

  /// Asks a node to shut down through its XML-RPC API, as `rosnode kill` does.
  static void killNode(const std::string& name) {
    XmlRpc::XmlRpcValue args;
    XmlRpc::XmlRpcValue result;
    XmlRpc::XmlRpcValue payload;
    args[0] = ros::this_node::getName();
    args[1] = name;
    ASSERT_TRUE(ros::master::execute("lookupNode", args, result, payload, true)) << name;
    std::string host;
    uint32_t port = 0;
    ASSERT_TRUE(ros::network::splitURI(static_cast<std::string>(payload), host, port));
    XmlRpc::XmlRpcClient client(host.c_str(), static_cast<int>(port), "/");
    XmlRpc::XmlRpcValue shutdown_args;
    shutdown_args[0] = ros::this_node::getName();
    shutdown_args[1] = "killed by the fault test";
    ASSERT_TRUE(client.execute("shutdown", shutdown_args, result)) << name;
  }

  Scenario scenario_;
  ControllerDesign design_;
  int axes_;
  double true_max_xi_ = 0.0;
  double true_min_separation_ = std::numeric_limits<double>::infinity();
  int truth_samples_ = 0;
  double max_applied_jump_ = 0.0;  ///< largest ||u(t_k) - u(t_{k-1})|| the plant applied
  bool applied_finite_ = true;
  std::deque<std::pair<double, double>> applied_norms_;  ///< (t, ||u||) the plant applied

 private:
  void onLeaderOdom(const nav_msgs::Odometry::ConstPtr& msg) {
    const std::lock_guard<std::mutex> lock(mutex_);
    leader_ = *msg;
    have_leader_ = true;
  }

  void onFollowerOdom(const nav_msgs::Odometry::ConstPtr& msg) {
    const std::lock_guard<std::mutex> lock(mutex_);
    if (!have_leader_ || leader_.header.stamp != msg->header.stamp) {
      // Pair the two agents' samples of the same tick only (the first tick's, stamped 0, can
      // come before any leader sample: never pair it with the empty message).
      return;
    }
    Eigen::VectorXd leader;
    Eigen::VectorXd follower;
    if (!stateFromOdometryMsg(leader_, axes_, &leader) ||
        !stateFromOdometryMsg(*msg, axes_, &follower)) {
      ADD_FAILURE() << "non-finite odometry";
      return;
    }
    const Eigen::VectorXd xi = leader - follower - scenario_.controller.separation;
    true_max_xi_ = std::max(true_max_xi_, xi.norm());
    true_min_separation_ = std::min(true_min_separation_, (leader - follower).head(axes_).norm());
    ++truth_samples_;
  }

  void onAppliedCommand(const geometry_msgs::AccelStamped::ConstPtr& msg) {
    const std::lock_guard<std::mutex> lock(mutex_);
    Eigen::VectorXd u;
    std::string why;
    if (!commandFromAccelMsg(*msg, axes_, &u, &why)) {
      applied_finite_ = false;
      return;
    }
    if (have_applied_) {
      max_applied_jump_ = std::max(max_applied_jump_, (u - last_applied_).norm());
    }
    last_applied_ = u;
    have_applied_ = true;
    applied_norms_.emplace_back(msg->header.stamp.toSec(), u.norm());
  }

  nav_msgs::Odometry leader_;
  bool have_leader_ = false;  ///< leader_ holds a received sample
  Eigen::VectorXd last_applied_;
  bool have_applied_ = false;
  ros::Subscriber leader_subscriber_;
  ros::Subscriber follower_subscriber_;
  ros::Subscriber applied_subscriber_;
};

TEST_F(FaultTest, SafetyUnderSensorFaults) { expectSafeRun(); }

TEST_F(FaultTest, FallbackAcrossAnOutage) {
  const double outage_end = param("outage_start") + param("outage_duration");
  expectSafeRun();
  const testing::StatusRecord r = record();
  EXPECT_GT(r.fallback_ticks, 0);
  EXPECT_EQ(r.modes.count(FollowerStatus::MODE_MEASUREMENT_LOST), 1U);
  EXPECT_GT(r.last_time, outage_end);
  EXPECT_EQ(r.last.mode, FollowerStatus::MODE_TRACKING) << r.last.mode_name;
  EXPECT_FALSE(r.last.fallback);
  // Diagnostics: OK while tracking, ERROR in the fallback, OK again after it.
  const std::lock_guard<std::mutex> lock(mutex_);
  int phase = 0;
  for (const auto& status : follower_diagnostics_) {
    if (phase == 0 && status.level == diagnostic_msgs::DiagnosticStatus::OK) {
      phase = 1;
    } else if (phase == 1 && status.level == diagnostic_msgs::DiagnosticStatus::ERROR &&
               status.message.find("measurement lost") != std::string::npos) {
      phase = 2;
    } else if (phase == 2 && status.level == diagnostic_msgs::DiagnosticStatus::OK) {
      phase = 3;
    }
  }
  EXPECT_EQ(phase, 3) << "diagnostics did not go OK -> ERROR (measurement lost) -> OK";
}

TEST_F(FaultTest, LeaderKilled) {
  const double kill_time = param("kill_time");
  ASSERT_TRUE(waitFor([this] { return record_.last.leader_fresh; }, param("wall_deadline")));
  ASSERT_TRUE(waitForStatusTime(kill_time, param("wall_deadline")));
  killNode("/leader_node");
  ASSERT_TRUE(waitFor([this] { return record_.last.mode == FollowerStatus::MODE_LEADER_LOST; },
                      param("wall_deadline")))
      << "the follower did not report the leader lost; mode " << record().last.mode_name;
  const int count_at_loss = record().count;
  expectSafeRun();
  const testing::StatusRecord r = record();
  EXPECT_GT(r.count, count_at_loss + 100) << "the follower stopped publishing";
  EXPECT_EQ(r.last.mode, FollowerStatus::MODE_LEADER_LOST) << r.last.mode_name;
  EXPECT_FALSE(r.last.leader_fresh);
}

TEST_F(FaultTest, FollowerRespawn) {
  const double kill_time = param("kill_time");
  ASSERT_TRUE(waitForStatusTime(kill_time, param("wall_deadline")));
  killNode("/follower/controller");
  // The respawned follower's statuses restart their count of rejected measurements and resume
  // from a new first measurement: wait for statuses well after the kill.
  expectSafeRun();
  const testing::StatusRecord r = record();
  EXPECT_EQ(r.last.mode, FollowerStatus::MODE_TRACKING) << r.last.mode_name;
  const double limit = scenario_.controller.acceleration_limit;
  ASSERT_TRUE(std::isfinite(limit)) << "set an acceleration_limit for this test";
  const std::lock_guard<std::mutex> lock(mutex_);
  EXPECT_LE(max_applied_jump_, limit * (1.0 + 1e-9));
  // The plant held zero after the kill while no follower commanded: the restart happened.
  int zero_ticks = 0;
  for (const auto& [t, norm] : applied_norms_) {
    zero_ticks += t > kill_time && norm == 0.0 ? 1 : 0;
  }
  EXPECT_GT(zero_ticks, 0);
}

}  // namespace
}  // namespace projection_collision_avoidance
