/// rostest: the command adapter alone (test/rostest/command_adapter.test). Parameters of the test
/// node:
///   ~control_rate     the adapter's ~control_rate (Hz)
///   ~look_ahead       its ~unicycle/look_ahead (m)
///   ~command_timeout  its ~command_timeout (s)
///   ~stops            stop messages to see once the commands end
///   ~tolerance        on the converted values
///   ~wall_deadline    wall seconds to wait for each condition
///   ~turn             yaw (rad) of the static transform world -> turned/odom (this test
///                     publishes it), the odometry frame of the adapter `adapter_turned`, whose
///                     commands are in world
///   ~frame_tolerance  on the turned accelerations (m/s^2) and on the velocity commands'
///                     direction (the component across the expected direction over the norm)
///   ~unjoined_time    wall seconds of commands to `adapter_unjoined` (odometry in lonely/odom,
///                     commands in world, no transform) over which it warns exactly once

#include <cmath>
#include <functional>
#include <limits>
#include <map>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <geometry_msgs/AccelStamped.h>
#include <geometry_msgs/TransformStamped.h>
#include <geometry_msgs/Twist.h>
#include <geometry_msgs/TwistStamped.h>
#include <geometry_msgs/Vector3Stamped.h>
#include <gtest/gtest.h>
#include <nav_msgs/Odometry.h>
#include <ros/ros.h>
#include <rosgraph_msgs/Log.h>
#include <tf2_ros/static_transform_broadcaster.h>

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

/// An adapter (topics under /@p robot) whose odometry is in another frame than the commands.
class CommandFrameTest : public testing::RosTestFixture {
 protected:
  /// One command's answers: the acceleration (setpoint_accel) and velocity (cmd_vel_stamped).
  struct Answer {
    Eigen::Vector2d acceleration = Eigen::Vector2d::Constant(std::nan(""));
    Eigen::Vector2d velocity = Eigen::Vector2d::Constant(std::nan(""));
    std::string velocity_frame;
    bool complete() const { return !acceleration.hasNaN() && !velocity.hasNaN(); }
  };

  void connect(const std::string& robot, const std::string& odometry_frame) {
    robot_ = robot;
    odometry_frame_ = odometry_frame;
    command_publisher_ = nh_.advertise<geometry_msgs::AccelStamped>("/" + robot + "/command", 10);
    odometry_publisher_ = nh_.advertise<nav_msgs::Odometry>("/" + robot + "/odom", 10);
    stamped_subscriber_ =
        nh_.subscribe("/" + robot + "/cmd_vel_stamped", 100, &CommandFrameTest::onStamped, this);
    accel_subscriber_ =
        nh_.subscribe("/" + robot + "/setpoint_accel", 100, &CommandFrameTest::onAccel, this);
    log_subscriber_ = nh_.subscribe("/rosout", 1000, &CommandFrameTest::onLog, this);
    ASSERT_TRUE(waitFor(
        [this] {
          return command_publisher_.getNumSubscribers() > 0 &&
                 odometry_publisher_.getNumSubscribers() > 0 &&
                 stamped_subscriber_.getNumPublishers() > 0 &&
                 accel_subscriber_.getNumPublishers() > 0 && log_subscriber_.getNumPublishers() > 0;
        },
        param("wall_deadline")))
        << "the adapter " << robot << " and the test never connected";
  }

  /// The robot at rest, facing the odometry frame's +x, then a command (ax, ay) in world; waits
  /// for its answers (~wall_deadline) and returns them (incomplete: none came).
  Answer command(double ax, double ay) {
    nav_msgs::Odometry odom;
    odom.header.stamp = ros::Time::now();
    odom.header.frame_id = odometry_frame_;
    odom.child_frame_id = robot_ + "/base_link";
    odom.pose.pose.orientation.w = 1.0;
    odometry_publisher_.publish(odom);
    geometry_msgs::AccelStamped command;
    command.header.stamp = ros::Time::now();
    command.header.frame_id = "world";
    command.accel.linear.x = ax;
    command.accel.linear.y = ay;
    command_publisher_.publish(command);
    const ros::Time stamp = command.header.stamp;
    waitFor([&] { return answers_[stamp].complete(); }, param("wall_deadline"));
    const std::lock_guard<std::mutex> lock(mutex_);
    return answers_[stamp];
  }

  /// Whether @p v points along @p direction (m/s, up to ~frame_tolerance of ‖v‖ across it).
  bool along(const Eigen::Vector2d& v, const Eigen::Vector2d& direction) {
    const Eigen::Vector2d unit = direction.normalized();
    const double across = v.x() * unit.y() - v.y() * unit.x();
    return v.dot(unit) > 0.0 && std::abs(across) <= param("frame_tolerance") * v.norm();
  }

  std::vector<rosgraph_msgs::Log> warnings_;  ///< the adapter's WARN lines naming ~world_frame

 private:
  void onStamped(const geometry_msgs::TwistStamped::ConstPtr& msg) {
    const std::lock_guard<std::mutex> lock(mutex_);
    Answer& answer = answers_[msg->header.stamp];
    answer.velocity = {msg->twist.linear.x, msg->twist.linear.y};
    answer.velocity_frame = msg->header.frame_id;
  }
  void onAccel(const geometry_msgs::Vector3Stamped::ConstPtr& msg) {
    const std::lock_guard<std::mutex> lock(mutex_);
    answers_[msg->header.stamp].acceleration = {msg->vector.x, msg->vector.y};
  }
  void onLog(const rosgraph_msgs::Log::ConstPtr& msg) {
    const std::lock_guard<std::mutex> lock(mutex_);
    if (msg->name == "/adapter_" + robot_ && msg->level == rosgraph_msgs::Log::WARN &&
        msg->msg.find("~world_frame") != std::string::npos) {
      warnings_.push_back(*msg);
    }
  }

  std::string robot_;
  std::string odometry_frame_;
  std::map<ros::Time, Answer> answers_;  ///< by the command's stamp
  ros::Publisher command_publisher_;
  ros::Publisher odometry_publisher_;
  ros::Subscriber stamped_subscriber_;
  ros::Subscriber accel_subscriber_;
  ros::Subscriber log_subscriber_;
};

TEST_F(CommandFrameTest, TurnsACommandInTheFollowersWorldIntoTheOdometryFrame) {
  ASSERT_NO_FATAL_FAILURE(connect("turned", "turned/odom"));
  const double turn = param("turn");
  const double tolerance = param("frame_tolerance");
  // world -> turned/odom is turned by `turn`: the world acceleration (1, 0) is
  // (cos turn, -sin turn) in turned/odom, and so is the velocity command it drives.
  const Eigen::Vector2d expected(std::cos(turn), -std::sin(turn));
  geometry_msgs::TransformStamped transform;
  transform.header.stamp = ros::Time::now();
  transform.header.frame_id = "world";
  transform.child_frame_id = "turned/odom";
  transform.transform.translation.x = 1.0;  // the start pose: a translation acts on no command
  transform.transform.translation.y = 2.0;
  transform.transform.rotation.z = std::sin(0.5 * turn);
  transform.transform.rotation.w = std::cos(0.5 * turn);
  tf2_ros::StaticTransformBroadcaster broadcaster;
  broadcaster.sendTransform(transform);
  // Until the transform and the odometry have reached the adapter and the velocity commands
  // made before are outweighed (each command adds a T to the velocity).
  const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(param("wall_deadline"));
  Answer answer;
  do {
    answer = command(1.0, 0.0);
    ASSERT_TRUE(answer.complete()) << "no answer from the adapter";
  } while (
      ros::WallTime::now() < deadline &&
      !((answer.acceleration - expected).norm() < tolerance && along(answer.velocity, expected)));
  EXPECT_NEAR(answer.acceleration.x(), expected.x(), tolerance);
  EXPECT_NEAR(answer.acceleration.y(), expected.y(), tolerance);
  EXPECT_TRUE(along(answer.velocity, expected)) << answer.velocity.transpose();
  EXPECT_EQ(answer.velocity_frame, "turned/odom");
  const std::lock_guard<std::mutex> lock(mutex_);
  EXPECT_TRUE(warnings_.empty()) << warnings_.front().msg;
}

TEST_F(CommandFrameTest, WarnsOnceAndCommandsWhenNoTransformJoinsTheFrames) {
  ASSERT_NO_FATAL_FAILURE(connect("unjoined", "lonely/odom"));
  const double tolerance = param("frame_tolerance");
  // Commands for ~unjoined_time s: each used as it is, one warning after the grace time.
  const ros::WallTime end = ros::WallTime::now() + ros::WallDuration(param("unjoined_time"));
  std::size_t answered = 0;
  while (ros::ok() && ros::WallTime::now() < end) {
    const Answer answer = command(0.0, 2.0);
    ASSERT_TRUE(answer.complete()) << "no answer from the adapter";
    if (answer.velocity.norm() > 0.0) {  // once the odometry has reached the adapter
      EXPECT_NEAR(answer.acceleration.x(), 0.0, tolerance);
      EXPECT_NEAR(answer.acceleration.y(), 2.0, tolerance);
      EXPECT_TRUE(along(answer.velocity, Eigen::Vector2d(0.0, 1.0))) << answer.velocity.transpose();
      ++answered;
    }
  }
  EXPECT_GT(answered, 0U) << "no command converted";
  ASSERT_TRUE(waitFor([this] { return !warnings_.empty(); }, param("wall_deadline")))
      << "the adapter never warned that tf does not join the frames";
  const std::lock_guard<std::mutex> lock(mutex_);
  EXPECT_EQ(warnings_.size(), 1U);
  const std::string& text = warnings_.front().msg;
  EXPECT_NE(text.find("'world'"), std::string::npos) << text;
  EXPECT_NE(text.find("'lonely/odom'"), std::string::npos) << text;
}

}  // namespace
}  // namespace projection_collision_avoidance
