/// rostest: the plant's vehicle kinds (test/rostest/plant_vehicles.test): follower_1 a velocity-
/// controlled vehicle (lag τ_v, fixed heading ψ, Twists in its body frame), follower_2 a unicycle
/// (lag τ_u, initial heading θ_0), follower_3 a velocity-controlled vehicle without lag taking
/// world-frame Twists, on ROS time. Parameters of the test node (SI units):
///   ~rate, ~command_timeout        the plant's
///   ~command_rate                  Hz of the cmd_vel streams sent
///   ~velocity_lag, ~velocity_heading, ~unicycle_lag, ~unicycle_heading,
///   ~world_velocity_heading        the plant's ~vehicles
///   ~velocity_command              m/s along the body x axis of follower_1
///   ~lag_fraction, ~lag_fraction_tolerance  (v(τ) − v0) / (v_cmd − v0) expected: 1 − e^(−1)
///   ~rest_speed                    m/s below which follower_1 counts as at rest
///   ~unicycle_speed, ~unicycle_yaw_rate     the unicycle's (v, ω): a circle of radius v / ω
///   ~settle_time, ~arc_time        s after the first command before, and over which, the circle
///                                  is fitted
///   ~radius_tolerance              m, on the fitted radius and every sample's distance to it
///   ~exact_tolerance               on what the plant computes exactly (twists, measurements)
///   ~stale_slack                   s, delivery and scheduling slack of the stop after a timeout
///   ~stale_lead                    s the stop may come early: the plant's tick that received the
///                                  last command may lag its receipt
///   ~wall_deadline                 wall s to wait for each condition

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Dense>
#include <gtest/gtest.h>
#include <ros/ros.h>
#include <tf2_ros/buffer.h>
#include <tf2_ros/transform_listener.h>

#include "plant_vehicles_fixture.h"

namespace projection_collision_avoidance {
namespace {

using testing::AgentRecord;
using testing::AppliedSample;
using testing::firstMove;
using testing::kAgents;
using testing::kLeader;
using testing::kUnicycle;
using testing::kVelocity;
using testing::kWorldVelocity;
using testing::OdomSample;
using testing::PlantVehiclesTest;
using testing::twistOf;

TEST_F(PlantVehiclesTest, OdometryAndTfCarryTheHeadingAsRealBasesPublishIt) {
  ASSERT_TRUE(waitFor([&] { return records_[kVelocity].odom.size() > 10; }, deadline_));
  ASSERT_TRUE(waitFor([&] { return records_[kUnicycle].odom.size() > 10; }, deadline_));
  const double headings[] = {0.0, param("velocity_heading"), param("unicycle_heading"),
                             param("world_velocity_heading")};
  for (const int agent : {kLeader, kVelocity, kUnicycle, kWorldVelocity}) {
    const AgentRecord r = record(agent);
    for (const auto& [stamp, s] : r.odom) {
      ASSERT_EQ(s.frame, "world");
      ASSERT_EQ(s.child_frame, kAgents[agent]);
      ASSERT_TRUE(s.finite);
      ASSERT_TRUE(s.roll_pitch_zero);
      ASSERT_NEAR(s.quaternion_norm, 1.0, tolerance_);
      if (agent != kUnicycle || s.t <= firstMove(r)) {
        ASSERT_NEAR(testing::angleBetween(s.yaw, headings[agent]), 0.0, tolerance_)
            << kAgents[agent] << " at " << s.t;
      }
    }
  }
  // tf world -> the agent's frame: the odometry's pose, the yaw included.
  tf2_ros::Buffer buffer;
  tf2_ros::TransformListener listener(buffer);
  for (const int agent : {kVelocity, kUnicycle}) {
    ASSERT_TRUE(waitFor([&] { return buffer.canTransform("world", kAgents[agent], ros::Time(0)); },
                        deadline_));
    const double after = record(agent).lastTime();  // a sample the listener was there for
    ASSERT_TRUE(waitForOdom(agent, after + 0.05));
    const OdomSample s = record(agent).odom.rbegin()->second;
    ros::Time stamp;
    stamp.fromNSec(static_cast<std::uint64_t>(s.ns));
    ASSERT_TRUE(
        waitFor([&] { return buffer.canTransform("world", kAgents[agent], stamp); }, deadline_))
        << kAgents[agent];
    const geometry_msgs::TransformStamped t =
        buffer.lookupTransform("world", kAgents[agent], stamp);
    const auto& x = t.transform.translation;
    EXPECT_LE((Eigen::Vector3d(x.x, x.y, x.z) - s.position).norm(), tolerance_);
    EXPECT_NEAR(testing::angleBetween(testing::yawOf(t.transform.rotation), s.yaw), 0.0,
                tolerance_);
  }
}

TEST_F(PlantVehiclesTest, VelocityVehicleFollowsItsBodyFrameCommandWithItsLag) {
  const double rest = param("rest_speed");
  const double quiet = waitForStop(kVelocity);
  ASSERT_TRUE(waitFor(
      [&] {
        return !records_[kVelocity].odom.empty() &&
               records_[kVelocity].odom.rbegin()->second.linear.norm() < rest;
      },
      deadline_));
  const double tau = param("velocity_lag");
  const double psi = param("velocity_heading");
  const double vc = param("velocity_command");
  const auto commands = stream(kVelocity, false);
  commands->set(twistOf(vc, 0.0, 0.0, 0.0, 0.0, 0.3));  // angular ignored
  const double start = firstNonZeroApplied(kVelocity, quiet);
  ASSERT_TRUE(waitForOdom(kVelocity, start));
  // Ticks of integration counted by the odometry's header.seq: on wall time a plant held off by
  // a loaded machine drops ticks (its stamps jump; scenario time runs slower), so the stamps
  // would overstate the time the lag acted.
  const long lag_ticks = std::lround(tau * param("rate"));
  const OdomSample first = record(kVelocity).nearest(start);
  ASSERT_TRUE(
      waitFor([&] { return records_[kVelocity].messagesAfter(first, 6 * lag_ticks) != nullptr; },
              deadline_));
  const AgentRecord r = record(kVelocity);
  for (const AppliedSample& a : r.applied) {  // the body command turned into the world frame
    if (a.t >= start && a.t <= start + 6.0 * tau) {
      ASSERT_EQ(a.frame, "world");
      ASSERT_LE((a.linear - vc * Eigen::Vector3d(std::cos(psi), std::sin(psi), 0.0)).norm(),
                tolerance_);
    }
  }
  const OdomSample& at_tau = *r.messagesAfter(first, lag_ticks);
  const OdomSample& settled = *r.messagesAfter(first, 6 * lag_ticks);
  // Seconds the lag acted: τ and 6τ unless a message was lost on the way.
  const double acted_tau = static_cast<double>(at_tau.seq - first.seq) / param("rate");
  const double acted_settled = static_cast<double>(settled.seq - first.seq) / param("rate");
  EXPECT_GE(AgentRecord::between(first, at_tau), acted_tau - 1e-6);  // stamps never run slower
  const double v0 = first.linear.x();
  // The fraction after τ is 1 − e^(−1); after t, 1 − e^(−t/τ) = 1 − (1 − fraction)^(t/τ).
  EXPECT_NEAR((at_tau.linear.x() - v0) / (vc - v0),
              1.0 - std::pow(1.0 - param("lag_fraction"), acted_tau / tau),
              param("lag_fraction_tolerance"));
  EXPECT_NEAR(at_tau.linear.y(), 0.0, rest);  // along the body x axis
  EXPECT_NEAR(settled.linear.x(), vc,
              std::abs(vc - v0) * std::exp(-acted_settled / tau) + tolerance_);
  EXPECT_TRUE(settled.angular.isZero(0.0));
  const Eigen::Vector3d moved = settled.position - first.position;
  EXPECT_NEAR(testing::angleBetween(std::atan2(moved.y(), moved.x()), psi), 0.0, 1e-3);
  EXPECT_GT(checkMeasurements(kVelocity), 100);
}

TEST_F(PlantVehiclesTest, WorldFrameTwistsAreTakenAsTheyAreWithoutLag) {
  const double psi = param("world_velocity_heading");
  const Eigen::Vector3d command(0.3, -0.4, 0.0);
  const double quiet = waitForStop(kWorldVelocity);
  const auto commands = stream(kWorldVelocity, false);
  commands->set(twistOf(command.x(), command.y(), 7.0, 0.0, 0.0, 1.0));  // z: beyond the 2 axes
  const double start = firstNonZeroApplied(kWorldVelocity, quiet);
  ASSERT_TRUE(waitForOdom(kWorldVelocity, start + 0.5));
  const AgentRecord r = record(kWorldVelocity);
  for (const AppliedSample& a : r.applied) {
    if (a.t >= start && a.t <= start + 0.5) {
      ASSERT_EQ(a.frame, "world");
      ASSERT_EQ(a.linear, command);
    }
  }
  for (const auto& [stamp, s] : r.odom) {  // τ = 0: the command's velocity from the next tick
    if (s.t > start + 0.005 && s.t <= start + 0.5) {
      ASSERT_LE((s.worldVelocity() - command).norm(), tolerance_) << s.t;
      ASSERT_NEAR(s.linear.x(), std::cos(psi) * command.x() + std::sin(psi) * command.y(),
                  tolerance_);
      ASSERT_NEAR(s.linear.y(), -std::sin(psi) * command.x() + std::cos(psi) * command.y(),
                  tolerance_);
    }
  }
  EXPECT_GT(checkMeasurements(kWorldVelocity), 10);
}

TEST_F(PlantVehiclesTest, UnicycleDrivesACircleOfRadiusVOverOmega) {
  const double v = param("unicycle_speed");
  const double omega = param("unicycle_yaw_rate");
  const double quiet = waitForStop(kUnicycle);
  const auto commands = stream(kUnicycle, true);
  commands->set(twistOf(v, 5.0, -1.0, 3.0, 2.0, omega));  // only linear.x and angular.z count
  const double start = firstNonZeroApplied(kUnicycle, quiet);
  const double from = start + param("settle_time");
  const double to = from + param("arc_time");
  ASSERT_TRUE(waitForOdom(kUnicycle, to));
  const AgentRecord r = record(kUnicycle);
  for (const AppliedSample& a : r.applied) {
    if (a.t >= start && a.t <= to) {
      ASSERT_EQ(a.frame, "follower_2");
      ASSERT_EQ(a.linear, Eigen::Vector3d(v, 0.0, 0.0));
      ASSERT_EQ(a.angular, Eigen::Vector3d(0.0, 0.0, omega));
    }
  }
  // Kasa's fit: x² + y² + D x + E y + F = 0 in the least-squares sense.
  std::vector<Eigen::Vector2d> points;
  const OdomSample* previous = nullptr;
  for (const auto& [stamp, s] : r.odom) {
    if (s.t < from || s.t > to) {
      continue;
    }
    ASSERT_NEAR(s.linear.x(), v, tolerance_);
    ASSERT_EQ(s.linear.y(), 0.0);
    ASSERT_NEAR(s.angular.z(), omega, tolerance_);
    if (previous != nullptr) {  // the chord's direction is the heading halfway
      const Eigen::Vector3d chord = s.position - previous->position;
      const double middle = previous->yaw + 0.5 * testing::angleBetween(s.yaw, previous->yaw);
      ASSERT_NEAR(testing::angleBetween(std::atan2(chord.y(), chord.x()), middle), 0.0, 1e-6);
    }
    previous = &s;
    points.push_back(s.position.head<2>());
  }
  ASSERT_GT(points.size(), 100U);
  Eigen::MatrixXd a(points.size(), 3);
  Eigen::VectorXd b(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) {
    a.row(static_cast<Eigen::Index>(i)) << points[i].x(), points[i].y(), 1.0;
    b(static_cast<Eigen::Index>(i)) = -points[i].squaredNorm();
  }
  const Eigen::Vector3d fit = a.colPivHouseholderQr().solve(b);
  const Eigen::Vector2d centre = -0.5 * fit.head<2>();
  const double radius = std::sqrt(centre.squaredNorm() - fit(2));
  const double tolerance = param("radius_tolerance");
  EXPECT_NEAR(radius, v / omega, tolerance);
  for (const Eigen::Vector2d& p : points) {
    ASSERT_NEAR((p - centre).norm(), v / omega, tolerance);
  }
  EXPECT_GT(checkMeasurements(kUnicycle), 100);
}

TEST_F(PlantVehiclesTest, AStaleCommandStopsBothVehicles) {
  const double timeout = param("command_timeout");
  const double h = 1.0 / param("rate");
  const double quiet[] = {0.0, waitForStop(kVelocity), waitForStop(kUnicycle)};
  auto velocity_commands = stream(kVelocity, true);
  auto unicycle_commands = stream(kUnicycle, false);
  velocity_commands->set(twistOf(0.5, 0.0, 0.0, 0.0, 0.0, 0.0));
  unicycle_commands->set(twistOf(0.5, 0.0, 0.0, 0.0, 0.0, 0.0));
  firstNonZeroApplied(kVelocity, quiet[kVelocity]);
  firstNonZeroApplied(kUnicycle, quiet[kUnicycle]);
  const double last_sent[] = {0.0, velocity_commands->stop().toSec(),
                              unicycle_commands->stop().toSec()};
  for (const int agent : {kVelocity, kUnicycle}) {
    const double stop = stopAfterLastMove(agent);
    EXPECT_GE(stop - last_sent[agent], timeout - h - param("stale_lead")) << kAgents[agent];
    EXPECT_LE(stop - last_sent[agent], timeout + param("stale_slack")) << kAgents[agent];
    const double tau = param(agent == kVelocity ? "velocity_lag" : "unicycle_lag");
    // The decay over ticks counted by header.seq (stamps jump where a loaded plant dropped some).
    const long lag_ticks = std::lround(tau * param("rate"));
    ASSERT_TRUE(waitForOdom(agent, stop));
    const OdomSample at_stop = record(agent).nearest(stop);
    ASSERT_TRUE(
        waitFor([&] { return records_[agent].messagesAfter(at_stop, 6 * lag_ticks) != nullptr; },
                deadline_));
    const AgentRecord r = record(agent);
    for (const AppliedSample& a : r.applied) {
      ASSERT_TRUE(a.t < stop || a.isZero()) << kAgents[agent] << " at " << a.t;
    }
    const OdomSample& later = *r.messagesAfter(at_stop, 6 * lag_ticks);
    const double acted = static_cast<double>(later.seq - at_stop.seq) * h;
    EXPECT_GT(at_stop.linear.norm(), 0.1);
    EXPECT_NEAR(later.linear.norm(), at_stop.linear.norm() * std::exp(-acted / tau), tolerance_);
  }
}

TEST_F(PlantVehiclesTest, NonFiniteTwistsAreRefusedWithoutEndingTheNode) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  const double quiet[] = {0.0, waitForStop(kVelocity), waitForStop(kUnicycle)};
  auto velocity_valid = stream(kVelocity, true);
  auto unicycle_valid = stream(kUnicycle, false);
  auto velocity_bad = stream(kVelocity, false);
  auto unicycle_bad = stream(kUnicycle, true);
  velocity_valid->set(twistOf(0.3, 0.0, 0.0, 0.0, 0.0, 0.0));
  unicycle_valid->set(twistOf(0.3, 0.0, 0.0, 0.0, 0.0, 0.2));
  const double start = std::max(firstNonZeroApplied(kVelocity, quiet[kVelocity]),
                                firstNonZeroApplied(kUnicycle, quiet[kUnicycle]));
  const geometry_msgs::Twist bad[] = {twistOf(nan, 0, 0, 0, 0, 0), twistOf(0, 0, 0, inf, 0, 0),
                                      twistOf(0, -inf, 0, 0, 0, 0), twistOf(0, 0, 0, 0, 0, nan),
                                      twistOf(0, 0, nan, 0, nan, 0)};
  for (int i = 0; i < 200; ++i) {  // 1 s of bad Twists on both topics of both vehicles
    for (const geometry_msgs::Twist& twist : bad) {
      velocity_bad->sendOnce(twist);
      unicycle_bad->sendOnce(twist);
      velocity_valid->sendOnce(twist);
      unicycle_valid->sendOnce(twist);
    }
    waitFor([] { return false; }, 0.005);
  }
  const double end = ros::Time::now().toSec();
  for (const int agent : {kVelocity, kUnicycle}) {
    ASSERT_TRUE(waitForOdom(agent, end + 1.0)) << kAgents[agent] << ": the plant ended";
    const AgentRecord r = record(agent);
    const AppliedSample* reference = nullptr;
    for (const AppliedSample& a : r.applied) {
      if (a.t >= start && a.t <= end + 1.0) {
        reference = reference != nullptr ? reference : &a;
        ASSERT_EQ(a.linear, reference->linear) << kAgents[agent] << " at " << a.t;
        ASSERT_EQ(a.angular, reference->angular) << kAgents[agent] << " at " << a.t;
      }
    }
    ASSERT_NE(reference, nullptr);
    EXPECT_FALSE(reference->isZero());
    for (const auto& [stamp, s] : r.odom) {
      ASSERT_TRUE(s.finite) << kAgents[agent] << " at " << s.t;
    }
  }
}

}  // namespace
}  // namespace projection_collision_avoidance
