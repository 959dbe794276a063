#pragma once

/// @file
/// The fixture of test_plant_vehicles: what it keeps of the plant's outputs (odometry, applied
/// velocity commands, relative measurements), waiting on them, and the measurement check.

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <iterator>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <geometry_msgs/Quaternion.h>
#include <geometry_msgs/TwistStamped.h>
#include <gtest/gtest.h>
#include <nav_msgs/Odometry.h>
#include <ros/ros.h>

#include "projection_collision_avoidance/RelativeMeasurement.h"

#include "command_stream.h"
#include "test_common.h"

namespace projection_collision_avoidance {
namespace testing {

/// Yaw (rad) of a quaternion: atan2(2 (w z + x y), 1 − 2 (y² + z²)).
inline double yawOf(const geometry_msgs::Quaternion& q) {
  return std::atan2(2.0 * (q.w * q.z + q.x * q.y), 1.0 - 2.0 * (q.y * q.y + q.z * q.z));
}

/// a − b wrapped to [−π, π].
inline double angleBetween(double a, double b) { return std::remainder(a - b, 2.0 * M_PI); }

/// One odometry message.
struct OdomSample {
  double t = 0.0;         ///< stamp (s; about 0.2 µs resolution at today's epoch times)
  std::int64_t ns = 0;    ///< stamp (ns), for exact differences
  std::uint32_t seq = 0;  ///< header.seq: roscpp numbers every message its publisher sends
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  double yaw = 0.0;
  double quaternion_norm = 0.0;
  bool roll_pitch_zero = false;                       ///< q.x = q.y = 0
  Eigen::Vector3d linear = Eigen::Vector3d::Zero();   ///< body frame
  Eigen::Vector3d angular = Eigen::Vector3d::Zero();  ///< body frame
  std::string frame;
  std::string child_frame;
  bool finite = true;

  /// The world velocity R_z(yaw) linear.
  Eigen::Vector3d worldVelocity() const {
    const double c = std::cos(yaw);
    const double s = std::sin(yaw);
    return {c * linear.x() - s * linear.y(), s * linear.x() + c * linear.y(), linear.z()};
  }
};

inline OdomSample sampleOf(const nav_msgs::Odometry& msg) {
  OdomSample s;
  s.t = msg.header.stamp.toSec();
  s.ns = static_cast<std::int64_t>(msg.header.stamp.toNSec());
  s.seq = msg.header.seq;
  const auto& p = msg.pose.pose.position;
  const auto& q = msg.pose.pose.orientation;
  s.position = Eigen::Vector3d(p.x, p.y, p.z);
  s.yaw = yawOf(q);
  s.quaternion_norm = std::sqrt(q.w * q.w + q.x * q.x + q.y * q.y + q.z * q.z);
  s.roll_pitch_zero = q.x == 0.0 && q.y == 0.0;
  const auto& v = msg.twist.twist.linear;
  const auto& w = msg.twist.twist.angular;
  s.linear = Eigen::Vector3d(v.x, v.y, v.z);
  s.angular = Eigen::Vector3d(w.x, w.y, w.z);
  s.frame = msg.header.frame_id;
  s.child_frame = msg.child_frame_id;
  s.finite = s.position.allFinite() && s.linear.allFinite() && s.angular.allFinite() &&
             std::isfinite(s.yaw);
  return s;
}

/// One applied command.
struct AppliedSample {
  double t = 0.0;
  std::string frame;
  Eigen::Vector3d linear = Eigen::Vector3d::Zero();
  Eigen::Vector3d angular = Eigen::Vector3d::Zero();
  bool isZero() const { return linear.isZero(0.0) && angular.isZero(0.0); }
};

/// What one agent published, by stamp (ns).
struct AgentRecord {
  std::map<std::int64_t, OdomSample> odom;
  std::vector<AppliedSample> applied;
  std::map<std::int64_t, Eigen::VectorXd> measurements;  ///< [p; v] of x_target − x_self

  /// Seconds from sample @p a to sample @p b, exact.
  static double between(const OdomSample& a, const OdomSample& b) {
    return 1e-9 * static_cast<double>(b.ns - a.ns);
  }

  double lastTime() const { return odom.empty() ? -1.0 : odom.rbegin()->second.t; }

  /// The first odometry sample published at least @p messages after @p from (the plant publishes
  /// one per tick, so these are ticks of integration, whatever the stamps say: a plant on wall
  /// time that falls behind drops ticks and its stamps jump), or nullptr.
  const OdomSample* messagesAfter(const OdomSample& from, long messages) const {
    for (auto it = odom.find(from.ns); it != odom.end(); ++it) {
      if (static_cast<long>(it->second.seq - from.seq) >= messages) {
        return &it->second;
      }
    }
    return nullptr;
  }

  /// The odometry sample whose stamp is nearest @p t (s).
  const OdomSample& nearest(double t) const {
    auto it = odom.lower_bound(static_cast<std::int64_t>(std::llround(t * 1e9)));
    if (it == odom.end()) {
      return std::prev(it)->second;
    }
    if (it != odom.begin() && t - std::prev(it)->second.t < it->second.t - t) {
      --it;
    }
    return it->second;
  }
};

/// The agents of plant_vehicles.test, by index.
constexpr int kLeader = 0;
constexpr int kVelocity = 1;
constexpr int kUnicycle = 2;
constexpr int kWorldVelocity = 3;  ///< a velocity vehicle without lag taking world-frame Twists
constexpr int kAgentCount = 4;
const char* const kAgents[] = {"leader", "follower_1", "follower_2", "follower_3"};

inline std::int64_t nanoseconds(const ros::Time& t) {
  return static_cast<std::int64_t>(t.toNSec());
}

/// Records the plant's outputs for the leader, follower_1 (velocity), follower_2 (unicycle) and
/// follower_3 (velocity, world-frame Twists).
class PlantVehiclesTest : public testing::RosTestFixture {
 protected:
  PlantVehiclesTest() {
    const ros::TransportHints hints = ros::TransportHints().tcpNoDelay();
    for (int i = 0; i < kAgentCount; ++i) {
      const std::string agent = std::string("/") + kAgents[i];
      subscribers_.push_back(nh_.subscribe<nav_msgs::Odometry>(
          agent + "/odom", 1000,
          [this, i](const nav_msgs::Odometry::ConstPtr& msg) {
            const std::lock_guard<std::mutex> lock(mutex_);
            records_[i].odom[nanoseconds(msg->header.stamp)] = testing::sampleOf(*msg);
          },
          nullptr, hints));
      if (i == kLeader) {
        continue;
      }
      subscribers_.push_back(nh_.subscribe<geometry_msgs::TwistStamped>(
          agent + "/applied_command", 1000,
          [this, i](const geometry_msgs::TwistStamped::ConstPtr& msg) {
            const std::lock_guard<std::mutex> lock(mutex_);
            const auto& l = msg->twist.linear;
            const auto& a = msg->twist.angular;
            records_[i].applied.push_back({msg->header.stamp.toSec(),
                                           msg->header.frame_id,
                                           {l.x, l.y, l.z},
                                           {a.x, a.y, a.z}});
          },
          nullptr, hints));
      subscribers_.push_back(nh_.subscribe<RelativeMeasurement>(
          agent + "/relative_measurement", 1000,
          [this, i](const RelativeMeasurement::ConstPtr& msg) {
            const std::lock_guard<std::mutex> lock(mutex_);
            Eigen::VectorXd state(4);
            state << msg->position[0], msg->position[1], msg->velocity[0], msg->velocity[1];
            records_[i].measurements[nanoseconds(msg->header.stamp)] = state;
          },
          nullptr, hints));
    }
    deadline_ = param("wall_deadline");
    tolerance_ = param("exact_tolerance");
  }

  /// A stream of commands to @p agent's cmd_vel (or cmd_vel_stamped), once the plant listens.
  std::unique_ptr<CommandStream> stream(int agent, bool stamped) {
    const std::string topic =
        std::string("/") + kAgents[agent] + (stamped ? "/cmd_vel_stamped" : "/cmd_vel");
    auto s = std::make_unique<CommandStream>(topic, stamped, param("command_rate"));
    EXPECT_TRUE(waitFor([&] { return s->heard(); }, deadline_)) << topic;
    return s;
  }

  /// Waits until @p agent's odometry reaches stamp @p t (s).
  bool waitForOdom(int agent, double t) {
    return waitFor([&] { return records_[agent].lastTime() >= t; }, deadline_);
  }

  /// Waits until @p agent applies no command (a previous test's is stale); returns that stamp.
  double waitForStop(int agent) {
    double quiet = -1.0;
    EXPECT_TRUE(waitFor(
        [&] {
          const std::vector<AppliedSample>& a = records_[agent].applied;
          quiet = a.empty() || !a.back().isZero() ? -1.0 : a.back().t;
          return quiet >= 0.0;
        },
        deadline_))
        << kAgents[agent] << " does not stop";
    return quiet;
  }

  /// Stamp (s) of @p agent's first non-zero applied command after @p after (s).
  double firstNonZeroApplied(int agent, double after) {
    double found = -1.0;
    EXPECT_TRUE(waitFor(
        [&] {
          for (const AppliedSample& a : records_[agent].applied) {
            if (a.t > after && !a.isZero()) {
              found = a.t;
              return true;
            }
          }
          return false;
        },
        deadline_))
        << kAgents[agent] << ": no command applied";
    return found;
  }

  /// Stamp (s) of @p agent's stop once its commands have ended: the first zero applied command
  /// after the last non-zero one. (A tick between a command's send and its receipt applies zero
  /// too; that zero comes before the command's non-zero ones, so it is not the stop.)
  double stopAfterLastMove(int agent) {
    double found = -1.0;
    EXPECT_TRUE(waitFor(
        [&] {
          const std::vector<AppliedSample>& a = records_[agent].applied;
          const auto last_move = std::find_if(a.rbegin(), a.rend(),
                                              [](const AppliedSample& s) { return !s.isZero(); });
          if (last_move == a.rend() || last_move == a.rbegin()) {
            return false;  // never moved, or still moving
          }
          found = last_move.base()->t;
          return true;
        },
        deadline_))
        << kAgents[agent] << ": no stop";
    return found;
  }

  AgentRecord record(int agent) {
    const std::lock_guard<std::mutex> lock(mutex_);
    return records_[agent];
  }

  /// Every measurement of @p agent with both odometries at its stamp is x_leader − x_agent, world
  /// velocities; returns how many were compared.
  int checkMeasurements(int agent) {
    const AgentRecord self = record(agent);
    const AgentRecord leader = record(kLeader);
    int compared = 0;
    for (const auto& [stamp, measured] : self.measurements) {
      const auto a = leader.odom.find(stamp);
      const auto b = self.odom.find(stamp);
      if (a == leader.odom.end() || b == self.odom.end()) {
        continue;
      }
      Eigen::VectorXd expected(4);
      expected << (a->second.position - b->second.position).head<2>(),
          (a->second.worldVelocity() - b->second.worldVelocity()).head<2>();
      EXPECT_LE((measured - expected).cwiseAbs().maxCoeff(), tolerance_) << kAgents[agent];
      ++compared;
    }
    return compared;
  }

  double deadline_ = 0.0;
  double tolerance_ = 0.0;
  AgentRecord records_[kAgentCount];
  std::vector<ros::Subscriber> subscribers_;
};

/// Stamp (s) of the first non-zero applied command, +inf if none.
inline double firstMove(const AgentRecord& r) {
  for (const AppliedSample& a : r.applied) {
    if (!a.isZero()) {
      return a.t;
    }
  }
  return std::numeric_limits<double>::infinity();
}

}  // namespace testing
}  // namespace projection_collision_avoidance
