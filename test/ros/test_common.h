#pragma once

/// @file
/// Fixture of the rostests: subscribes to what the follower publishes, and waits on conditions
/// with wall-clock deadlines (never fixed sleeps).

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <mutex>
#include <set>
#include <string>
#include <vector>

#include <diagnostic_msgs/DiagnosticArray.h>
#include <gtest/gtest.h>
#include <ros/ros.h>
#include <visualization_msgs/MarkerArray.h>

#include "projection_collision_avoidance/FollowerStatus.h"

namespace projection_collision_avoidance {
namespace testing {

/// Figures of the follower's status stream since the fixture started.
struct StatusRecord {
  int count = 0;
  double max_xi = 0.0;
  double max_xi_hat = 0.0;
  double min_separation = std::numeric_limits<double>::infinity();
  double max_command = 0.0;     ///< largest ||command|| (m/s^2)
  bool commands_finite = true;  ///< every command entry finite so far
  int fallback_ticks = 0;       ///< statuses with fallback set
  std::set<int> modes;          ///< FollowerStatus::mode values seen
  double last_time = 0.0;       ///< stamp of the latest status (s)
  int leader_age_count = 0;     ///< statuses with a finite leader_age
  double leader_age_sum = 0.0;  ///< s, their sum
  double max_leader_age = 0.0;  ///< s
  FollowerStatus last;
};

/// Adds one status to a record.
inline void addStatus(const FollowerStatus& msg, StatusRecord* record) {
  ++record->count;
  record->max_xi = std::max(record->max_xi, msg.xi_norm);
  record->max_xi_hat = std::max(record->max_xi_hat, msg.xi_hat_norm);
  record->min_separation = std::min(record->min_separation, msg.distance);
  double squared = 0.0;
  for (const double u : msg.command) {
    record->commands_finite = record->commands_finite && std::isfinite(u);
    squared += u * u;
  }
  record->max_command = std::max(record->max_command, std::sqrt(squared));
  record->fallback_ticks += msg.fallback ? 1 : 0;
  record->modes.insert(msg.mode);
  record->last_time = msg.header.stamp.toSec();
  if (std::isfinite(msg.leader_age)) {
    ++record->leader_age_count;
    record->leader_age_sum += msg.leader_age;
    record->max_leader_age = std::max(record->max_leader_age, msg.leader_age);
  }
  record->last = msg;
}

class FollowerTest : public ::testing::Test {
 protected:
  FollowerTest() : private_nh_("~") {
    status_subscriber_ = nh_.subscribe("/follower/status", 1000, &FollowerTest::onStatus, this);
    marker_subscriber_ = nh_.subscribe("/follower/markers", 10, &FollowerTest::onMarkers, this);
    diagnostics_subscriber_ =
        nh_.subscribe("/diagnostics", 100, &FollowerTest::onDiagnostics, this);
  }

  /// Spins until @p condition holds or @p wall_seconds pass; returns whether it held.
  bool waitFor(const std::function<bool()>& condition, double wall_seconds) {
    const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(wall_seconds);
    while (ros::ok() && ros::WallTime::now() < deadline) {
      ros::spinOnce();
      {
        const std::lock_guard<std::mutex> lock(mutex_);
        if (condition()) {
          return true;
        }
      }
      ros::WallDuration(0.002).sleep();
    }
    const std::lock_guard<std::mutex> lock(mutex_);
    return condition();
  }

  /// Waits until a status stamped at or after @p sim_seconds has arrived.
  bool waitForStatusTime(double sim_seconds, double wall_seconds) {
    return waitFor([this, sim_seconds] { return record_.last_time >= sim_seconds; }, wall_seconds);
  }

  StatusRecord record() {
    const std::lock_guard<std::mutex> lock(mutex_);
    return record_;
  }

  /// A <param> of the test node, failing the test if it is missing.
  double param(const std::string& key) {
    double value = 0.0;
    EXPECT_TRUE(private_nh_.getParam(key, value)) << "missing test parameter ~" << key;
    return value;
  }

  ros::NodeHandle nh_;
  ros::NodeHandle private_nh_;
  std::mutex mutex_;
  StatusRecord record_;
  visualization_msgs::MarkerArray markers_;
  bool have_markers_ = false;
  std::vector<diagnostic_msgs::DiagnosticStatus> follower_diagnostics_;

 private:
  void onStatus(const FollowerStatus::ConstPtr& msg) {
    const std::lock_guard<std::mutex> lock(mutex_);
    addStatus(*msg, &record_);
  }

  void onMarkers(const visualization_msgs::MarkerArray::ConstPtr& msg) {
    const std::lock_guard<std::mutex> lock(mutex_);
    markers_ = *msg;
    have_markers_ = true;
  }

  void onDiagnostics(const diagnostic_msgs::DiagnosticArray::ConstPtr& msg) {
    const std::lock_guard<std::mutex> lock(mutex_);
    for (const auto& status : msg->status) {
      if (status.name.find("follower controller") != std::string::npos) {
        follower_diagnostics_.push_back(status);
      }
    }
  }

  ros::Subscriber status_subscriber_;
  ros::Subscriber marker_subscriber_;
  ros::Subscriber diagnostics_subscriber_;
};

}  // namespace testing
}  // namespace projection_collision_avoidance
