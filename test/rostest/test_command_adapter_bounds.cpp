/// rostest (test/rostest/command_adapter.test, linked into test_command_adapter): hostile values
/// at the command adapter's inputs. A command of 1e308 m/s^2, one of 1.7e308 on two axes (turned
/// by tf, it overflows), odometry of 1000 m/s and of 1e300 m/s: every published output finite
/// and within the adapter's default limits, and the adapter still converting afterwards.
/// Parameters of the test node (besides those of test_command_adapter.cpp):
///   ~max_speed      the adapters' default ~velocity/max_speed and ~unicycle/max_speed (m/s)
///   ~max_yaw_rate   their default ~unicycle/max_yaw_rate (rad/s)
///   ~limit_tolerance  relative tolerance on the limits (rounding of the base-frame rotation)

#include <cmath>
#include <string>
#include <vector>

#include <geometry_msgs/AccelStamped.h>
#include <geometry_msgs/TransformStamped.h>
#include <geometry_msgs/Twist.h>
#include <geometry_msgs/TwistStamped.h>
#include <geometry_msgs/Vector3Stamped.h>
#include <gtest/gtest.h>
#include <nav_msgs/Odometry.h>
#include <ros/ros.h>
#include <tf2_ros/static_transform_broadcaster.h>

#include "test_common.h"

namespace projection_collision_avoidance {
namespace {

/// The adapter whose topics are under /@p robot: its every output recorded.
class AdapterBoundsTest : public testing::RosTestFixture {
 protected:
  void connect(const std::string& robot, const std::string& odometry_frame) {
    odometry_frame_ = odometry_frame;
    command_publisher_ = nh_.advertise<geometry_msgs::AccelStamped>("/" + robot + "/command", 10);
    odometry_publisher_ = nh_.advertise<nav_msgs::Odometry>("/" + robot + "/odom", 10);
    subscribers_.push_back(nh_.subscribe<geometry_msgs::Twist>(
        "/" + robot + "/cmd_vel", 1000, [this](const geometry_msgs::Twist::ConstPtr& msg) {
          const std::lock_guard<std::mutex> lock(mutex_);
          twists_.push_back(*msg);
        }));
    subscribers_.push_back(nh_.subscribe<geometry_msgs::TwistStamped>(
        "/" + robot + "/cmd_vel_stamped", 1000,
        [this](const geometry_msgs::TwistStamped::ConstPtr& msg) {
          const std::lock_guard<std::mutex> lock(mutex_);
          stamped_.push_back(*msg);
        }));
    subscribers_.push_back(nh_.subscribe<geometry_msgs::Vector3Stamped>(
        "/" + robot + "/setpoint_accel", 1000,
        [this](const geometry_msgs::Vector3Stamped::ConstPtr& msg) {
          const std::lock_guard<std::mutex> lock(mutex_);
          accels_.push_back(*msg);
        }));
    ASSERT_TRUE(waitFor(
        [this] {
          return command_publisher_.getNumSubscribers() > 0 &&
                 odometry_publisher_.getNumSubscribers() > 0 &&
                 subscribers_[1].getNumPublishers() > 0;
        },
        param("wall_deadline")))
        << "the adapter " << robot << " and the test never connected";
  }

  /// Odometry stamped now: facing x, body-frame velocity (@p vx, 0), yaw rate @p omega.
  void publishOdometry(double vx, double omega) {
    nav_msgs::Odometry odom;
    odom.header.stamp = ros::Time::now();
    odom.header.frame_id = odometry_frame_;
    odom.child_frame_id = "base_link";
    odom.pose.pose.orientation.w = 1.0;
    odom.twist.twist.linear.x = vx;
    odom.twist.twist.angular.z = omega;
    odometry_publisher_.publish(odom);
  }

  /// Publishes the command (@p ax, @p ay) in world; whether its answer (cmd_vel_stamped with its
  /// stamp) came within ~wall_deadline.
  bool answered(double ax, double ay) {
    geometry_msgs::AccelStamped command;
    command.header.stamp = ros::Time::now();
    command.header.frame_id = "world";
    command.accel.linear.x = ax;
    command.accel.linear.y = ay;
    command_publisher_.publish(command);
    const ros::Time stamp = command.header.stamp;
    return waitFor(
        [&] {
          for (const geometry_msgs::TwistStamped& t : stamped_) {
            if (t.header.stamp == stamp) {
              return true;
            }
          }
          return false;
        },
        param("wall_deadline"));
  }

  /// Odometry at rest and a small command until the adapter answers it with a nonzero velocity
  /// (the odometry has reached it) and, when @p turned, an acceleration turned off the world's
  /// y axis (tf joins the frames).
  void warmUp(bool turned) {
    const ros::WallTime end = ros::WallTime::now() + ros::WallDuration(param("wall_deadline"));
    while (ros::WallTime::now() < end) {
      publishOdometry(0.0, 0.0);
      ASSERT_TRUE(answered(0.0, 1.0)) << "the adapter does not answer";
      const std::lock_guard<std::mutex> lock(mutex_);
      const geometry_msgs::Twist& t = stamped_.back().twist;
      const bool moving = t.linear.x != 0.0 || t.linear.y != 0.0 || t.angular.z != 0.0;
      if (moving && (!turned || (!accels_.empty() && std::abs(accels_.back().vector.x) > 0.1))) {
        return;
      }
    }
    FAIL() << "the adapter never used the odometry";
  }

  /// The hostile sequence (@p turned: see warmUp()); then every output recorded is checked.
  void hostileSequence(bool turned) {
    ASSERT_NO_FATAL_FAILURE(warmUp(turned));
    publishOdometry(1000.0, 0.0);  // a spike of 1000 m/s
    EXPECT_TRUE(answered(1.0, 0.0));
    publishOdometry(1e300, 1e300);
    EXPECT_TRUE(answered(1.0, 0.0));
    publishOdometry(0.0, 0.0);
    EXPECT_TRUE(answered(1e308, 0.0));
    EXPECT_TRUE(answered(1.7e308, 1.7e308));  // turned by tf: an overflow
    EXPECT_TRUE(answered(-1e308, 1e308));
    publishOdometry(0.0, 0.0);
    EXPECT_TRUE(answered(0.0, 1.0)) << "the adapter stopped answering";
  }

  /// Every recorded output finite; velocities within ~max_speed, yaw rates within ~max_yaw_rate.
  void expectBounded() {
    const double slack = 1.0 + param("limit_tolerance");
    const double max_speed = param("max_speed") * slack;
    const double max_yaw_rate = param("max_yaw_rate") * slack;
    const auto check = [&](const geometry_msgs::Twist& t, const char* topic) {
      const double speed = std::hypot(std::hypot(t.linear.x, t.linear.y), t.linear.z);
      EXPECT_TRUE(std::isfinite(speed) && std::isfinite(t.angular.z))
          << topic << ": " << t.linear.x << " " << t.linear.y << " " << t.angular.z;
      EXPECT_LE(speed, max_speed) << topic;
      EXPECT_LE(std::abs(t.angular.z), max_yaw_rate) << topic;
    };
    const std::lock_guard<std::mutex> lock(mutex_);
    EXPECT_GT(stamped_.size(), 5U);
    for (const geometry_msgs::TwistStamped& t : stamped_) {
      check(t.twist, "cmd_vel_stamped");
    }
    for (const geometry_msgs::Twist& t : twists_) {
      check(t, "cmd_vel");
    }
    for (const geometry_msgs::Vector3Stamped& a : accels_) {
      EXPECT_TRUE(std::isfinite(a.vector.x) && std::isfinite(a.vector.y) &&
                  std::isfinite(a.vector.z))
          << "setpoint_accel: " << a.vector.x << " " << a.vector.y;
    }
  }

 private:
  std::string odometry_frame_;
  ros::Publisher command_publisher_;
  ros::Publisher odometry_publisher_;
  std::vector<ros::Subscriber> subscribers_;
  std::vector<geometry_msgs::Twist> twists_;
  std::vector<geometry_msgs::TwistStamped> stamped_;
  std::vector<geometry_msgs::Vector3Stamped> accels_;
};

TEST_F(AdapterBoundsTest, AVelocityAdapterInTheBaseFrameSendsFiniteCommandsWithinItsLimits) {
  // Its odometry in hostile/odom, turned from world by ~turn.
  const double turn = param("turn");
  geometry_msgs::TransformStamped transform;
  transform.header.stamp = ros::Time::now();
  transform.header.frame_id = "world";
  transform.child_frame_id = "hostile/odom";
  transform.transform.rotation.z = std::sin(0.5 * turn);
  transform.transform.rotation.w = std::cos(0.5 * turn);
  tf2_ros::StaticTransformBroadcaster broadcaster;
  broadcaster.sendTransform(transform);
  ASSERT_NO_FATAL_FAILURE(connect("hostile_velocity", "hostile/odom"));
  ASSERT_NO_FATAL_FAILURE(hostileSequence(true));
  expectBounded();
}

TEST_F(AdapterBoundsTest, AUnicycleAdapterSendsFiniteCommandsWithinItsLimits) {
  ASSERT_NO_FATAL_FAILURE(connect("hostile_unicycle", "world"));
  ASSERT_NO_FATAL_FAILURE(hostileSequence(false));
  expectBounded();
}

}  // namespace
}  // namespace projection_collision_avoidance
