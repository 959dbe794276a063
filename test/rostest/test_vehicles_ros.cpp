/// rostest: followers that are vehicles (test/rostest/vehicles.test, launch/vehicles.launch): each
/// on ~input odometry, driving its robot through a command_adapter. Parameters of the test node:
///   ~followers           N
///   ~end_time            s of simulated time to watch (the push toward the followers included)
///   ~look_ahead          m, each follower's controlled point ahead of its axle (0: holonomic)
///   ~target_look_ahead   m, the same of its target (0: the leader)
///   ~min_statuses        statuses each follower must have published by end_time
///   ~final_xi            m; ||xi|| of every follower at end_time at most this (formation kept)
///   ~wall_deadline       wall seconds to wait for end_time
/// Checks: the controlled points never inside the perimeter (every status' distance), ||xi||
/// within xi_max at every status, the formation converged at the end, no fallback step, and
/// the axles (from the plant's odometry) never closer than the perimeter less the look-aheads.
/// Odometry in another frame than `world` (vehicles.launch odom_frames:=true: each follower's
/// own odom frame) is moved into it with the test's own tf2 lookup.

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nav_msgs/Odometry.h>
#include <ros/ros.h>
#include <tf2/exceptions.h>
#include <tf2_eigen/tf2_eigen.h>
#include <tf2_ros/buffer.h>
#include <tf2_ros/transform_listener.h>

#include "projection_collision_avoidance/FollowerStatus.h"

#include "test_common.h"

namespace projection_collision_avoidance {
namespace {

class VehiclesTest : public testing::RosTestFixture {
 protected:
  VehiclesTest() : followers_(static_cast<int>(param("followers"))) {
    for (int i = 1; i <= followers_; ++i) {
      const std::string name = "follower_" + std::to_string(i);
      status_subscribers_.push_back(nh_.subscribe<FollowerStatus>(
          "/" + name + "/status", 1000,
          [this, i](const FollowerStatus::ConstPtr& msg) { onStatus(i, *msg); }));
      odometry_subscribers_.push_back(nh_.subscribe<nav_msgs::Odometry>(
          "/" + name + "/odom", 1000,
          [this, i](const nav_msgs::Odometry::ConstPtr& msg) { onOdometry(i, *msg); }));
    }
    odometry_subscribers_.push_back(nh_.subscribe<nav_msgs::Odometry>(
        "/leader/odom", 1000,
        [this](const nav_msgs::Odometry::ConstPtr& msg) { onOdometry(0, *msg); }));
  }

  void onStatus(int i, const FollowerStatus& msg) {
    const std::lock_guard<std::mutex> lock(mutex_);
    testing::addStatus(msg, &records_[i]);
    perimeter_[i] = msg.perimeter;
    xi_max_[i] = msg.xi_max;
    max_margin_violation_[i] = std::max(max_margin_violation_[i], msg.xi_norm - msg.xi_max);
    targets_[i] = msg.target;
  }

  /// Axle positions by stamp; the plant publishes every agent at each tick with one stamp.
  void onOdometry(int agent, const nav_msgs::Odometry& msg) {
    Eigen::Vector3d p(msg.pose.pose.position.x, msg.pose.pose.position.y, msg.pose.pose.position.z);
    if (msg.header.frame_id != "world") {
      try {
        p = tf2::transformToEigen(
                tf_buffer_.lookupTransform("world", msg.header.frame_id, ros::Time(0))) *
            p;
      } catch (const tf2::TransformException&) {
        return;  // its static transform not heard yet
      }
    }
    const std::lock_guard<std::mutex> lock(mutex_);
    positions_[msg.header.stamp.toNSec()][agent] = {p.x(), p.y()};
  }

  /// The agent index of a status' target name ("leader" or "follower_<j>").
  static int indexOf(const std::string& target) {
    return target == "leader" ? 0 : std::stoi(target.substr(target.find('_') + 1));
  }

  int followers_;
  std::map<int, testing::StatusRecord> records_;
  std::map<int, double> perimeter_;
  std::map<int, double> xi_max_;
  std::map<int, double> max_margin_violation_;
  std::map<int, std::string> targets_;
  std::map<std::uint64_t, std::map<int, std::array<double, 2>>> positions_;
  std::vector<ros::Subscriber> status_subscribers_;
  std::vector<ros::Subscriber> odometry_subscribers_;
  tf2_ros::Buffer tf_buffer_;
  tf2_ros::TransformListener tf_listener_{tf_buffer_};
};

TEST_F(VehiclesTest, TheFormationIsKeptAndNoPerimeterEntered) {
  const double end_time = param("end_time");
  ASSERT_TRUE(waitFor(
      [&] {
        if (static_cast<int>(records_.size()) < followers_) {
          return false;
        }
        for (const auto& entry : records_) {
          if (entry.second.last_time < end_time) {
            return false;
          }
        }
        return true;
      },
      param("wall_deadline")))
      << "not every follower reached the end time";
  const std::lock_guard<std::mutex> lock(mutex_);
  const double look_ahead = param("look_ahead");
  const double target_look_ahead = param("target_look_ahead");
  for (int i = 1; i <= followers_; ++i) {
    const testing::StatusRecord& r = records_[i];
    SCOPED_TRACE("follower_" + std::to_string(i));
    EXPECT_GE(r.count, static_cast<int>(param("min_statuses")));
    EXPECT_GE(r.min_separation, perimeter_[i]) << "the controlled points inside the perimeter";
    EXPECT_LE(r.max_xi, xi_max_[i]) << "||xi|| beyond xi_max";
    EXPECT_EQ(r.fallback_ticks, 0);
    EXPECT_LE(r.last.xi_norm, param("final_xi")) << "the formation did not converge";
    EXPECT_TRUE(r.commands_finite);
    // The axles, from the plant's odometry at the same ticks.
    const int target = indexOf(targets_[i]);
    const double l_target = target == 0 ? 0.0 : target_look_ahead;
    double min_axles = std::numeric_limits<double>::infinity();
    int pairs = 0;
    for (const auto& tick : positions_) {
      const auto self = tick.second.find(i);
      const auto other = tick.second.find(target);
      if (self == tick.second.end() || other == tick.second.end()) {
        continue;
      }
      ++pairs;
      min_axles = std::min(min_axles, std::hypot(self->second[0] - other->second[0],
                                                 self->second[1] - other->second[1]));
    }
    EXPECT_GT(pairs, 0);
    EXPECT_GE(min_axles, perimeter_[i] - look_ahead - l_target)
        << "the axles closer than the perimeter less the look-ahead distances";
    // The figures, in the test's XML report (rosunit-vehicles_<kind>_<topology>.xml).
    const std::string prefix = "follower_" + std::to_string(i) + "_";
    const auto record = [&prefix](const std::string& key, double value) {
      ::testing::Test::RecordProperty(prefix + key, std::to_string(value));
    };
    record("statuses", r.count);
    record("min_distance_controlled_points_m", r.min_separation);
    record("perimeter_m", perimeter_[i]);
    record("min_distance_axles_m", min_axles);
    record("max_xi_m", r.max_xi);
    record("xi_max_m", xi_max_[i]);
    record("final_xi_m", r.last.xi_norm);
  }
}

}  // namespace
}  // namespace projection_collision_avoidance
