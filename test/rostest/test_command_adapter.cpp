/// rostest: the command adapter alone (test/rostest/command_adapter.test). Parameters of the test
/// node:
///   ~control_rate     the adapter's ~control_rate (Hz)
///   ~look_ahead       its ~unicycle/look_ahead (m)
///   ~command_timeout  its ~command_timeout (s)
///   ~stops            stop messages to see once the commands end
///   ~tolerance        on the converted values
///   ~wall_deadline    wall seconds to wait for each condition

#include <cmath>
#include <limits>
#include <vector>

#include <geometry_msgs/AccelStamped.h>
#include <geometry_msgs/Twist.h>
#include <geometry_msgs/TwistStamped.h>
#include <geometry_msgs/Vector3Stamped.h>
#include <gtest/gtest.h>
#include <nav_msgs/Odometry.h>
#include <ros/ros.h>

#include "test_common.h"

namespace projection_collision_avoidance {
namespace {

class CommandAdapterTest : public testing::RosTestFixture {
 protected:
  CommandAdapterTest() {
    command_publisher_ = nh_.advertise<geometry_msgs::AccelStamped>("/follower/command", 10);
    odometry_publisher_ = nh_.advertise<nav_msgs::Odometry>("/robot/odom", 10);
    twist_subscriber_ = nh_.subscribe("/robot/cmd_vel", 100, &CommandAdapterTest::onTwist, this);
    stamped_subscriber_ =
        nh_.subscribe("/robot/cmd_vel_stamped", 100, &CommandAdapterTest::onStamped, this);
    accel_subscriber_ =
        nh_.subscribe("/robot/setpoint_accel", 100, &CommandAdapterTest::onAccel, this);
  }

  bool connected() {
    return waitFor(
        [this] {
          return command_publisher_.getNumSubscribers() > 0 &&
                 odometry_publisher_.getNumSubscribers() > 0 &&
                 twist_subscriber_.getNumPublishers() > 0 &&
                 stamped_subscriber_.getNumPublishers() > 0 &&
                 accel_subscriber_.getNumPublishers() > 0;
        },
        param("wall_deadline"));
  }

  /// The robot at rest at the origin, facing +x, stamped now, in world / base_link.
  void publishOdometry() {
    nav_msgs::Odometry odom;
    odom.header.stamp = ros::Time::now();
    odom.header.frame_id = "world";
    odom.child_frame_id = "base_link";
    odom.pose.pose.orientation.w = 1.0;
    odometry_publisher_.publish(odom);
  }

  /// A command (ax, ay) stamped now; returns the stamp.
  ros::Time publishCommand(double ax, double ay) {
    geometry_msgs::AccelStamped command;
    command.header.stamp = ros::Time::now();
    command.header.frame_id = "world";
    command.accel.linear.x = ax;
    command.accel.linear.y = ay;
    command_publisher_.publish(command);
    return command.header.stamp;
  }

  /// The stamped twist answering the command stamped @p stamp, or nullptr (mutex_ held).
  const geometry_msgs::TwistStamped* answer(const ros::Time& stamp) const {
    for (const geometry_msgs::TwistStamped& t : stamped_) {
      if (t.header.stamp == stamp) {
        return &t;
      }
    }
    return nullptr;
  }

  std::vector<geometry_msgs::Twist> twists_;
  std::vector<geometry_msgs::TwistStamped> stamped_;
  std::vector<geometry_msgs::Vector3Stamped> accels_;
  ros::Publisher command_publisher_;

 private:
  void onTwist(const geometry_msgs::Twist::ConstPtr& msg) {
    const std::lock_guard<std::mutex> lock(mutex_);
    twists_.push_back(*msg);
  }
  void onStamped(const geometry_msgs::TwistStamped::ConstPtr& msg) {
    const std::lock_guard<std::mutex> lock(mutex_);
    stamped_.push_back(*msg);
  }
  void onAccel(const geometry_msgs::Vector3Stamped::ConstPtr& msg) {
    const std::lock_guard<std::mutex> lock(mutex_);
    accels_.push_back(*msg);
  }

  ros::Publisher odometry_publisher_;
  ros::Subscriber twist_subscriber_;
  ros::Subscriber stamped_subscriber_;
  ros::Subscriber accel_subscriber_;
};

TEST_F(CommandAdapterTest, ConvertsEachCommandAndStopsOnceTheyEnd) {
  ASSERT_TRUE(connected()) << "the adapter and the test never connected";
  const double deadline = param("wall_deadline");
  const double tolerance = param("tolerance");
  const double period = 1.0 / param("control_rate");
  const double look_ahead = param("look_ahead");

  // A sideways acceleration of the look-ahead point turns the robot at rest: v = 0, and
  // omega = a T / l (the velocity anchored on the measured one, zero).
  ros::Time stamp;
  for (int attempt = 0; attempt < 50; ++attempt) {  // until the odometry has reached the adapter
    publishOdometry();
    stamp = publishCommand(0.0, 2.0);
    ASSERT_TRUE(waitFor([&] { return answer(stamp) != nullptr; }, deadline));
    const std::lock_guard<std::mutex> lock(mutex_);
    if (answer(stamp)->twist.angular.z != 0.0) {
      break;
    }
  }
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    const geometry_msgs::TwistStamped* t = answer(stamp);
    ASSERT_NE(t, nullptr);
    EXPECT_NEAR(t->twist.linear.x, 0.0, tolerance);
    EXPECT_NEAR(t->twist.angular.z, 2.0 * period / look_ahead, tolerance);
    EXPECT_EQ(t->header.frame_id, "base_link");  // a unicycle's command is in its base frame
    ASSERT_FALSE(accels_.empty());
    EXPECT_EQ(accels_.back().header.frame_id, "world");
    EXPECT_NEAR(accels_.back().vector.y, 2.0, tolerance);  // the acceleration as it is
    ASSERT_FALSE(twists_.empty());
    EXPECT_NEAR(twists_.back().angular.z, t->twist.angular.z, tolerance);
  }

  // Refused: a non-finite command and one of an axis the model lacks; the node runs on.
  geometry_msgs::AccelStamped bad;
  bad.header.frame_id = "world";
  bad.header.stamp = ros::Time::now();
  bad.accel.linear.x = std::numeric_limits<double>::quiet_NaN();
  command_publisher_.publish(bad);
  bad.accel.linear.x = 0.0;
  bad.accel.linear.z = 1.0;
  bad.header.stamp = ros::Time::now();
  command_publisher_.publish(bad);

  // No more commands: after ~command_timeout the stop, repeated: zero v and omega, zero
  // velocity, a braking (here zero: at rest) acceleration.
  std::size_t before = 0;
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    before = twists_.size();
  }
  const auto stops = static_cast<std::size_t>(param("stops"));
  ASSERT_TRUE(waitFor(
      [&] {
        std::size_t zeros = 0;
        for (std::size_t i = before; i < twists_.size(); ++i) {
          zeros += twists_[i].linear.x == 0.0 && twists_[i].angular.z == 0.0 ? 1 : 0;
        }
        return zeros >= stops;
      },
      param("command_timeout") + deadline))
      << "no repeated stop after the commands ended";
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    const geometry_msgs::Twist& last = twists_.back();
    EXPECT_EQ(last.linear.x, 0.0);
    EXPECT_EQ(last.angular.z, 0.0);
    EXPECT_EQ(accels_.back().vector.x, 0.0);
    EXPECT_EQ(accels_.back().vector.y, 0.0);
  }

  // Commands again: converted again (the node survived the refused ones).
  publishOdometry();
  const ros::Time again = publishCommand(1.0, 0.0);
  ASSERT_TRUE(waitFor([&] { return answer(again) != nullptr; }, deadline))
      << "the adapter stopped answering after refused commands";
  const std::lock_guard<std::mutex> lock(mutex_);
  EXPECT_NEAR(answer(again)->twist.linear.x, period, tolerance);
  EXPECT_NEAR(answer(again)->twist.angular.z, 0.0, tolerance);
}

}  // namespace
}  // namespace projection_collision_avoidance
