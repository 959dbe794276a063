// CommandFrame: a command in the follower's world frame turned into the adapter's world frame by
// the rotation tf2 holds, looked up again at most once a second; as it is in the world or base
// frame; as it is with one warning when tf2 does not join the frames. No master: a tf2 buffer
// filled by hand, steady times given.
#include <cmath>

#include <geometry_msgs/TransformStamped.h>
#include <gtest/gtest.h>
#include <ros/time.h>
#include <tf2_ros/buffer.h>

#include "adapter/CommandFrame.hpp"

namespace projection_collision_avoidance {
namespace {

constexpr double kTolerance = 1e-12;

/// A transform parent -> child turned by @p yaw (rad) about z.
geometry_msgs::TransformStamped turnedBy(const std::string& parent, const std::string& child,
                                         double yaw) {
  geometry_msgs::TransformStamped t;
  t.header.stamp = ros::Time(1.0);
  t.header.frame_id = parent;
  t.child_frame_id = child;
  t.transform.translation.x = 3.0;  // a translation does not act on an acceleration
  t.transform.rotation.z = std::sin(0.5 * yaw);
  t.transform.rotation.w = std::cos(0.5 * yaw);
  return t;
}

class CommandFrameTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() { ros::Time::init(); }

  /// (ax, ay) in @p frame into "robot/odom" (base "robot/base_link") at steady time @p now.
  Eigen::Vector2d toWorld(const std::string& frame, double ax, double ay, double now) {
    Eigen::VectorXd a(2);
    a << ax, ay;
    frame_.toWorld(frame, "robot/odom", "robot/base_link", now, &a);
    return a;
  }

  tf2_ros::Buffer buffer_;
  CommandFrame frame_{"/adapter", &buffer_, true};
};

TEST_F(CommandFrameTest, TurnsACommandByTheRotationIntoTheWorldFrame) {
  const double yaw = M_PI / 6.0;  // world -> robot/odom turned by 30°
  buffer_.setTransform(turnedBy("world", "robot/odom", yaw), "test", true);
  const Eigen::Vector2d a = toWorld("/world", 1.0, 0.0, 10.0);
  EXPECT_NEAR(a.x(), std::cos(yaw), kTolerance);  // R(-30°) (1, 0)
  EXPECT_NEAR(a.y(), -std::sin(yaw), kTolerance);
  EXPECT_TRUE(frame_.turned());
  EXPECT_TRUE(frame_.warning().empty());
}

TEST_F(CommandFrameTest, TurnsAThreeAxisCommandAndKeepsAFourthEntry) {
  buffer_.setTransform(turnedBy("world", "robot/odom", M_PI / 2.0), "test", true);
  Eigen::VectorXd a(3);
  a << 1.0, 0.0, 2.0;
  frame_.toWorld("world", "robot/odom", "", 0.0, &a);
  EXPECT_NEAR(a(0), 0.0, kTolerance);
  EXPECT_NEAR(a(1), -1.0, kTolerance);
  EXPECT_NEAR(a(2), 2.0, kTolerance);  // a turn about z leaves z
}

TEST_F(CommandFrameTest, TakesTheWorldTheBaseAndAnEmptyFrameAsTheyAre) {
  buffer_.setTransform(turnedBy("robot/odom", "robot/base_link", 1.0), "test", false);
  for (const char* frame :
       {"robot/odom", "/robot/odom", "robot/base_link", "/robot/base_link", ""}) {
    const Eigen::Vector2d a = toWorld(frame, 1.0, 2.0, 0.0);
    EXPECT_EQ(a.x(), 1.0) << frame;
    EXPECT_EQ(a.y(), 2.0) << frame;
    EXPECT_FALSE(frame_.turned()) << frame;
  }
  // No world frame known yet (no odometry): as it is, whatever the frame.
  Eigen::VectorXd a(2);
  a << 1.0, 2.0;
  frame_.toWorld("world", "", "", 0.0, &a);
  EXPECT_EQ(a(0), 1.0);
  EXPECT_EQ(a(1), 2.0);
  EXPECT_TRUE(frame_.warning().empty());
}

TEST_F(CommandFrameTest, WarnsOnceAfterTheGraceTimeWhenTfDoesNotJoinTheFrames) {
  const double grace = CommandFrame::kJoinGrace;
  for (double now = 0.0; now < grace - 0.05; now += 0.01) {  // within the grace time: silent
    const Eigen::Vector2d a = toWorld("world", 1.0, 2.0, now);
    EXPECT_EQ(a.x(), 1.0);
    EXPECT_EQ(a.y(), 2.0);
    ASSERT_TRUE(frame_.warning().empty()) << now;
  }
  // At the first lookup after it (they are kRetryPeriod apart until one succeeds).
  toWorld("world", 1.0, 2.0, grace + CommandFrame::kRetryPeriod);
  const std::string warning = frame_.warning();
  ASSERT_FALSE(warning.empty());
  EXPECT_NE(warning.find("~world_frame"), std::string::npos) << warning;
  EXPECT_NE(warning.find("'world'"), std::string::npos) << warning;
  EXPECT_NE(warning.find("'robot/odom'"), std::string::npos) << warning;
  const Eigen::Vector2d a = toWorld("world", 1.0, 2.0, grace + 0.6);  // still as it is
  EXPECT_EQ(a.x(), 1.0);
  EXPECT_EQ(a.y(), 2.0);
  EXPECT_FALSE(frame_.turned());
  // The transform comes: found at the next lookup (within a refresh period), the warning gone.
  buffer_.setTransform(turnedBy("world", "robot/odom", M_PI), "test", true);
  const Eigen::Vector2d turned =
      toWorld("world", 1.0, 2.0, grace + CommandFrame::kRetryPeriod + CommandFrame::kRefreshPeriod);
  EXPECT_NEAR(turned.x(), -1.0, kTolerance);
  EXPECT_NEAR(turned.y(), -2.0, kTolerance);
  EXPECT_TRUE(frame_.warning().empty());
}

TEST_F(CommandFrameTest, LooksTheRotationUpAgainAtMostOnceAPeriod) {
  buffer_.setTransform(turnedBy("world", "robot/odom", M_PI / 2.0), "test", false);
  EXPECT_NEAR(toWorld("world", 1.0, 0.0, 0.0).y(), -1.0, kTolerance);
  geometry_msgs::TransformStamped later = turnedBy("world", "robot/odom", M_PI);
  later.header.stamp = ros::Time(2.0);
  buffer_.setTransform(later, "test", false);
  // Within the period the rotation found is kept; after it, the latest.
  EXPECT_NEAR(toWorld("world", 1.0, 0.0, 0.5 * CommandFrame::kRefreshPeriod).y(), -1.0, kTolerance);
  EXPECT_NEAR(toWorld("world", 1.0, 0.0, CommandFrame::kRefreshPeriod).x(), -1.0, kTolerance);
}

}  // namespace
}  // namespace projection_collision_avoidance
