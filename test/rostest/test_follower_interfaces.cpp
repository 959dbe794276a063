/// rostest: what the follower publishes (status, markers, tf frames of the plant, diagnostics)
/// the frame of its command, and its dynamic_reconfigure interface, on the paper's Run 2.
/// Parameters of the test node:
///   ~wall_deadline  wall seconds to wait for each condition

#include <cmath>
#include <limits>
#include <set>
#include <string>

#include <dynamic_reconfigure/Reconfigure.h>
#include <geometry_msgs/AccelStamped.h>
#include <gtest/gtest.h>
#include <ros/ros.h>
#include <tf2_ros/buffer.h>
#include <tf2_ros/transform_listener.h>

#include "test_common.h"

namespace projection_collision_avoidance {
namespace {

using testing::FollowerTest;

/// Calls the follower's set_parameters service with one value; returns the configuration the
/// server answers with (the values in force afterwards).
dynamic_reconfigure::Config reconfigure(const std::string& name, double number, bool flag,
                                        bool is_bool) {
  dynamic_reconfigure::Reconfigure srv;
  if (is_bool) {
    dynamic_reconfigure::BoolParameter p;
    p.name = name;
    p.value = flag;
    srv.request.config.bools.push_back(p);
  } else {
    dynamic_reconfigure::DoubleParameter p;
    p.name = name;
    p.value = number;
    srv.request.config.doubles.push_back(p);
  }
  EXPECT_TRUE(ros::service::waitForService("/follower/controller/set_parameters", 30000));
  EXPECT_TRUE(ros::service::call("/follower/controller/set_parameters", srv));
  return srv.response.config;
}

double doubleOf(const dynamic_reconfigure::Config& config, const std::string& name) {
  for (const auto& p : config.doubles) {
    if (p.name == name) {
      return p.value;
    }
  }
  ADD_FAILURE() << name << " not in the configuration";
  return 0.0;
}

TEST_F(FollowerTest, PublishesStatusWithTheScenariosBounds) {
  ASSERT_TRUE(waitFor([this] { return record_.count >= 20; }, param("wall_deadline")));
  const FollowerStatus s = record().last;
  EXPECT_EQ(s.header.frame_id, "follower");
  EXPECT_TRUE(s.measurement_fresh);
  EXPECT_EQ(s.mode, FollowerStatus::MODE_TRACKING);
  EXPECT_EQ(s.mode_name, "tracking");
  EXPECT_FALSE(s.fallback);
  EXPECT_TRUE(std::isinf(s.acceleration_limit));  // none in the paper's scenario
  EXPECT_EQ(s.fallback_command.size(), 1u);
  EXPECT_EQ(s.xi.size(), 2u);
  EXPECT_EQ(s.xi_hat.size(), 2u);
  EXPECT_EQ(s.command.size(), 1u);
  EXPECT_DOUBLE_EQ(s.xi_max, 4.0);
  EXPECT_NEAR(s.xi_soft, 4.0 / std::sqrt(1.2), 1e-12);
  EXPECT_DOUBLE_EQ(s.perimeter, 1.0);
  EXPECT_NEAR(s.margin, s.xi_max - s.xi_norm, 1e-12);
  EXPECT_NEAR(s.command[0], s.baseline_command[0] + s.tracker_command[0] + s.feedforward_command[0],
              1e-12);
  EXPECT_TRUE(s.tracker_enabled);
  EXPECT_FALSE(s.command_saturated);
  EXPECT_FALSE(s.command_rate_limited);
  EXPECT_TRUE(std::isinf(s.jerk_limit));
  EXPECT_NEAR(s.distance, 5.0, 0.05);  // before the disturbance the follower holds its slot
}

TEST_F(FollowerTest, NamesTheMeasurementsFrameInTheCommand) {
  // The plant's relative measurements are in its world frame ("world"), and so is u_2: the
  // command says so (~follower_frame, "follower", names only the status and the markers).
  std::string frame;
  ros::Subscriber subscriber = nh_.subscribe<geometry_msgs::AccelStamped>(
      "/follower/command", 10, [&](const geometry_msgs::AccelStamped::ConstPtr& msg) {
        const std::lock_guard<std::mutex> lock(mutex_);
        frame = msg->header.frame_id;
      });
  ASSERT_TRUE(waitFor([&] { return !frame.empty(); }, param("wall_deadline")))
      << "no command from the follower";
  const std::lock_guard<std::mutex> lock(mutex_);
  EXPECT_EQ(frame, "world");
}

TEST_F(FollowerTest, PublishesMarkersInTheFollowerFrame) {
  ASSERT_TRUE(waitFor([this] { return have_markers_; }, param("wall_deadline")));
  const std::lock_guard<std::mutex> lock(mutex_);
  std::set<std::string> namespaces;
  for (const auto& marker : markers_.markers) {
    namespaces.insert(marker.ns);
    EXPECT_EQ(marker.header.frame_id, "follower");
    if (marker.ns == "perimeter") {
      EXPECT_DOUBLE_EQ(marker.scale.x, 2.0);      // diameter 2 alpha ||d||
      EXPECT_GT(marker.color.g, marker.color.r);  // green: the leader is outside the perimeter
    }
    if (marker.ns == "slot") {
      EXPECT_NEAR(marker.pose.position.x, 0.0, 0.05);  // the follower sits on its slot
    }
    if (marker.ns == "bound") {
      EXPECT_NE(marker.text.find("xi_max 4.00"), std::string::npos) << marker.text;
    }
  }
  EXPECT_EQ(namespaces, (std::set<std::string>{"perimeter", "slot", "cf_estimate", "bound"}));
}

TEST_F(FollowerTest, PlantPublishesTheAgentFrames) {
  tf2_ros::Buffer buffer;
  tf2_ros::TransformListener listener(buffer);
  geometry_msgs::TransformStamped leader;
  geometry_msgs::TransformStamped follower;
  ASSERT_TRUE(waitFor(
      [&] {
        if (!buffer.canTransform("world", "leader", ros::Time(0)) ||
            !buffer.canTransform("world", "follower", ros::Time(0))) {
          return false;
        }
        leader = buffer.lookupTransform("world", "leader", ros::Time(0));
        follower = buffer.lookupTransform("world", "follower", ros::Time(0));
        return true;
      },
      param("wall_deadline")));
  EXPECT_NEAR(leader.transform.translation.x - follower.transform.translation.x, 5.0, 0.05);
}

TEST_F(FollowerTest, PublishesDiagnostics) {
  ASSERT_TRUE(waitFor(
      [this] {
        return !follower_diagnostics_.empty() &&
               follower_diagnostics_.back().level == diagnostic_msgs::DiagnosticStatus::OK;
      },
      param("wall_deadline")));
  const std::lock_guard<std::mutex> lock(mutex_);
  std::set<std::string> keys;
  for (const auto& value : follower_diagnostics_.back().values) {
    keys.insert(value.key);
  }
  EXPECT_EQ(keys.count("xi_norm (m)"), 1u);
  EXPECT_EQ(keys.count("margin (m)"), 1u);
  EXPECT_EQ(keys.count("rejected_measurements"), 1u);
  EXPECT_EQ(keys.count("rejected_leader_broadcasts"), 1u);
  EXPECT_EQ(keys.count("mode"), 1u);
}

TEST_F(FollowerTest, ReconfigureSwitchesTheTrackerAndRefusesAnInvalidAlpha) {
  const double deadline = param("wall_deadline");
  ASSERT_TRUE(waitFor([this] { return record_.count > 0; }, deadline));

  reconfigure("tracker_enabled", 0.0, false, true);
  EXPECT_TRUE(waitFor([this] { return !record_.last.tracker_enabled; }, deadline));
  reconfigure("tracker_enabled", 0.0, true, true);
  EXPECT_TRUE(waitFor([this] { return record_.last.tracker_enabled; }, deadline));

  const dynamic_reconfigure::Config refused = reconfigure("alpha", 1.0, false, false);
  EXPECT_DOUBLE_EQ(doubleOf(refused, "alpha"), 0.2);  // the old value is kept
  const dynamic_reconfigure::Config accepted = reconfigure("alpha", 0.3, false, false);
  EXPECT_DOUBLE_EQ(doubleOf(accepted, "alpha"), 0.3);
  EXPECT_TRUE(waitFor([this] { return std::abs(record_.last.xi_max - 3.5) < 1e-12; }, deadline));
}

TEST_F(FollowerTest, ReconfigureFrequencyZeroRestoresTheFilesGainAndNeverStoresNonFinite) {
  const double deadline = param("wall_deadline");
  const auto gain_is = [this](const std::string& gain) {  // called by waitFor() with mutex_ held
    return !follower_diagnostics_.empty() &&
           testing::diagnosticValue(follower_diagnostics_.back(), "tracker_gain") == gain;
  };
  // Run 2's G_e = [10, 5]; (omega_n, zeta) = (2, 0.7) gives [omega_n^2, 2 zeta omega_n].
  ASSERT_TRUE(waitFor([&] { return gain_is("[10, 5]"); }, deadline));
  reconfigure("tracker_damping", 0.7, false, false);
  const dynamic_reconfigure::Config set =
      reconfigure("tracker_natural_frequency", 2.0, false, false);
  EXPECT_DOUBLE_EQ(doubleOf(set, "tracker_natural_frequency"), 2.0);
  EXPECT_TRUE(waitFor([&] { return gain_is("[4, 2.8]"); }, deadline));
  const dynamic_reconfigure::Config restored =
      reconfigure("tracker_natural_frequency", 0.0, false, false);
  EXPECT_DOUBLE_EQ(doubleOf(restored, "tracker_natural_frequency"), 0.0);
  EXPECT_TRUE(waitFor([&] { return gain_is("[10, 5]"); }, deadline));

  // NaN is refused, whether or not the value would be used, and never stored; an infinity is
  // clamped by dynamic_reconfigure to the range of cfg/Follower.cfg before the node sees it.
  for (const char* name : {"alpha", "epsilon", "tracker_damping", "tracker_natural_frequency"}) {
    // The configuration in force, from a call that changes nothing.
    const double before = doubleOf(reconfigure("tracker_damping", 0.7, false, false), name);
    const dynamic_reconfigure::Config refused = reconfigure(name, std::nan(""), false, false);
    EXPECT_DOUBLE_EQ(doubleOf(refused, name), before) << name;
    const dynamic_reconfigure::Config clamped =
        reconfigure(name, std::numeric_limits<double>::infinity(), false, false);
    EXPECT_TRUE(std::isfinite(doubleOf(clamped, name))) << name;
  }
  reconfigure("epsilon", 0.2, false, false);
  reconfigure("tracker_damping", 0.7, false, false);
  reconfigure("tracker_natural_frequency", 0.0, false, false);
  EXPECT_TRUE(waitFor([&] { return gain_is("[10, 5]"); }, deadline));
}

}  // namespace
}  // namespace projection_collision_avoidance
