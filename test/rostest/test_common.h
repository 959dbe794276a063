#pragma once

/// @file
/// Fixtures and helpers of the rostests' C++ programs (their main() is rostest_main.cpp): the
/// test node's parameters, waiting on conditions with wall-clock deadlines (never fixed sleeps),
/// and what the follower publishes.

#include <algorithm>
#include <cmath>
#include <cstdint>
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
#include "projection_collision_avoidance/RelativeMeasurement.h"

namespace projection_collision_avoidance {
namespace testing {

/// A <param> of the test node (read from @p private_nh, "~"), failing the test if it is missing.
inline double requiredParam(const ros::NodeHandle& private_nh, const std::string& key) {
  double value = 0.0;
  EXPECT_TRUE(private_nh.getParam(key, value)) << "missing test parameter ~" << key;
  return value;
}

/// The value of @p key in a diagnostic status, "(missing)" if it has none.
inline std::string diagnosticValue(const diagnostic_msgs::DiagnosticStatus& status,
                                   const std::string& key) {
  for (const auto& entry : status.values) {
    if (entry.key == key) {
      return entry.value;
    }
  }
  return "(missing)";
}

/// A valid 1-axis relative measurement in the world frame, stamped now.
inline RelativeMeasurement measurementNow(double position, double velocity) {
  RelativeMeasurement msg;
  msg.header.frame_id = "world";
  msg.header.stamp = ros::Time::now();
  msg.position = {position};
  msg.velocity = {velocity};
  return msg;
}

/// What the tests of the follower's steps keep of a status.
struct StatusSample {
  ros::Time stamp;
  std::uint64_t ticks = 0;
  std::uint32_t missed_periods = 0;
  std::uint32_t late_periods = 0;
  double tick_delay = 0.0;
  std::uint8_t mode = 0;
  bool fallback = false;
  std::vector<double> command;
};

inline StatusSample sampleOf(const FollowerStatus& msg) {
  StatusSample sample;
  sample.stamp = msg.header.stamp;
  sample.ticks = msg.ticks;
  sample.missed_periods = msg.missed_periods;
  sample.late_periods = msg.late_periods;
  sample.tick_delay = msg.tick_delay;
  sample.mode = msg.mode;
  sample.fallback = msg.fallback != 0;
  sample.command = msg.command;
  return sample;
}

/// Figures of the follower's status stream since the fixture started.
struct StatusRecord {
  int count = 0;
  double max_xi = 0.0;
  double max_xi_hat = 0.0;
  double min_separation = std::numeric_limits<double>::infinity();
  double max_command = 0.0;                ///< largest ||command|| (m/s^2)
  bool commands_finite = true;             ///< every command entry finite so far
  int fallback_ticks = 0;                  ///< statuses with fallback set
  std::set<int> modes;                     ///< FollowerStatus::mode values seen
  double last_time = 0.0;                  ///< stamp of the latest status (s)
  int leader_age_count = 0;                ///< statuses with a finite leader_age
  double leader_age_sum = 0.0;             ///< s, their sum
  double max_leader_age = 0.0;             ///< s
  int barrier_filter_count = 0;            ///< statuses with barrier_filter set
  int barrier_projected_count = 0;         ///< statuses with barrier_projected set
  int barrier_infeasible_count = 0;        ///< statuses with barrier_infeasible set
  std::set<std::string> binding_barriers;  ///< binding_barrier values seen ("" left out)
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
  record->barrier_filter_count += msg.barrier_filter ? 1 : 0;
  record->barrier_projected_count += msg.barrier_projected ? 1 : 0;
  record->barrier_infeasible_count += msg.barrier_infeasible ? 1 : 0;
  if (!msg.binding_barrier.empty()) {
    record->binding_barriers.insert(msg.binding_barrier);
  }
  record->last = msg;
}

/// The test node's handles and parameters, and waiting with a deadline: the base of the fixtures.
class RosTestFixture : public ::testing::Test {
 protected:
  RosTestFixture() : private_nh_("~") {}

  /// Spins until @p condition (called with mutex_ held) holds or @p wall_seconds pass; returns
  /// whether it held.
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

  /// A <param> of the test node, failing the test if it is missing.
  double param(const std::string& key) { return requiredParam(private_nh_, key); }

  ros::NodeHandle nh_;
  ros::NodeHandle private_nh_;
  std::mutex mutex_;  ///< guards what the subscribers' callbacks write
};

/// Subscribes to what the follower (/follower) publishes: status, markers, diagnostics.
class FollowerTest : public RosTestFixture {
 protected:
  FollowerTest() {
    status_subscriber_ = nh_.subscribe("/follower/status", 1000, &FollowerTest::onStatus, this);
    marker_subscriber_ = nh_.subscribe("/follower/markers", 10, &FollowerTest::onMarkers, this);
    diagnostics_subscriber_ =
        nh_.subscribe("/diagnostics", 100, &FollowerTest::onDiagnostics, this);
  }

  /// Waits until a status stamped at or after @p sim_seconds has arrived.
  bool waitForStatusTime(double sim_seconds, double wall_seconds) {
    return waitFor([this, sim_seconds] { return record_.last_time >= sim_seconds; }, wall_seconds);
  }

  StatusRecord record() {
    const std::lock_guard<std::mutex> lock(mutex_);
    return record_;
  }

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
