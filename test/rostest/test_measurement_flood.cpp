/// rostest: a flood of valid relative measurements (~flood_rate, 10 kHz) on a lone follower does
/// not stall its control timer: the statuses it publishes, one per tick, keep their rate, and
/// their stamps (the tick times) no large gap. Parameters (<param>s of the test node):
///   ~flood_rate       Hz at which measurements are published
///   ~flood_seconds    wall seconds of flooding
///   ~control_rate     the follower's control rate (Hz)
///   ~min_rate_share   the status rate during the flood must reach this share of control_rate
///   ~max_status_gap   s; no two consecutive statuses during the flood may be further apart
///   ~min_flood_share  the publisher must reach this share of flood_rate (else the test did not
///                     flood and says so)

#include <algorithm>
#include <atomic>
#include <vector>

#include <gtest/gtest.h>
#include <ros/ros.h>

#include "projection_collision_avoidance/FollowerStatus.h"
#include "projection_collision_avoidance/RelativeMeasurement.h"

#include "test_common.h"

namespace projection_collision_avoidance {
namespace {

TEST(MeasurementFlood, ControlTimerKeepsItsRate) {
  ros::NodeHandle nh;
  ros::NodeHandle private_nh("~");
  const double flood_rate = testing::requiredParam(private_nh, "flood_rate");
  const double flood_seconds = testing::requiredParam(private_nh, "flood_seconds");
  const double control_rate = testing::requiredParam(private_nh, "control_rate");

  std::mutex mutex;
  std::vector<ros::Time> arrivals;  // tick times (stamps, wall clock here) of the statuses
  FollowerStatus last;
  ros::Subscriber subscriber =
      nh.subscribe<FollowerStatus>("/status", 10000, [&](const FollowerStatus::ConstPtr& msg) {
        const std::lock_guard<std::mutex> lock(mutex);
        arrivals.push_back(msg->header.stamp);
        last = *msg;
      });
  ros::Publisher publisher = nh.advertise<RelativeMeasurement>("/relative_measurement", 1000);
  ros::AsyncSpinner spinner(1);
  spinner.start();

  RelativeMeasurement msg;
  msg.header.frame_id = "world";
  msg.position = {5.0};
  msg.velocity = {0.0};
  // Wait (with a deadline) until the follower is connected and tracking.
  const ros::WallTime ready_deadline = ros::WallTime::now() + ros::WallDuration(20.0);
  bool ready = false;
  while (!ready && ros::WallTime::now() < ready_deadline) {
    msg.header.stamp = ros::Time::now();
    publisher.publish(msg);
    ros::WallDuration(0.01).sleep();
    const std::lock_guard<std::mutex> lock(mutex);
    ready = !arrivals.empty() && last.mode == FollowerStatus::MODE_TRACKING;
  }
  ASSERT_TRUE(ready) << "the follower never tracked";

  // Flood from this thread, paced on wall time; count what was published.
  std::size_t statuses_before = 0;
  {
    const std::lock_guard<std::mutex> lock(mutex);
    statuses_before = arrivals.size();
  }
  const ros::WallTime start = ros::WallTime::now();
  const ros::WallTime end = start + ros::WallDuration(flood_seconds);
  long published = 0;
  for (ros::WallTime now = start; now < end; now = ros::WallTime::now()) {
    const long due = static_cast<long>((now - start).toSec() * flood_rate);
    for (; published <= due; ++published) {
      msg.header.stamp = ros::Time::now();
      msg.position[0] = 5.0 + 1e-3 * static_cast<double>(published % 100);
      publisher.publish(msg);
    }
    ros::WallDuration(0.0005).sleep();  // bursts of ~5 messages, leaving CPU to the follower
  }
  const double elapsed = (ros::WallTime::now() - start).toSec();
  // The ticks within the flood, by their stamps: delays in delivering the statuses to this
  // (busy) process do not count against the follower.
  const ros::Time flood_start(start.toSec());
  const ros::Time flood_end = flood_start + ros::Duration(elapsed);
  // Wait (with a deadline) for the statuses of the flood's last ticks to arrive.
  const ros::WallTime drain_deadline = ros::WallTime::now() + ros::WallDuration(5.0);
  for (bool drained = false; !drained && ros::WallTime::now() < drain_deadline;) {
    ros::WallDuration(0.01).sleep();
    const std::lock_guard<std::mutex> lock(mutex);
    drained = !arrivals.empty() && arrivals.back() > flood_end;
  }
  std::vector<ros::Time> during;
  {
    const std::lock_guard<std::mutex> lock(mutex);
    for (std::size_t i = statuses_before == 0 ? 0 : statuses_before - 1; i < arrivals.size(); ++i) {
      if (arrivals[i] <= flood_end) {
        during.push_back(arrivals[i]);
      }
    }
  }
  double max_gap = 0.0;
  for (std::size_t i = 1; i < during.size(); ++i) {
    max_gap = std::max(max_gap, (during[i] - during[i - 1]).toSec());
  }
  const double flood_achieved = static_cast<double>(published) / elapsed;
  const double status_rate = static_cast<double>(during.size() - 1) / elapsed;
  ROS_INFO(
      "flood: %ld measurements in %.2f s (%.0f Hz); follower statuses %.1f Hz, largest gap "
      "%.4f s (control rate %.0f Hz)",
      published, elapsed, flood_achieved, status_rate, max_gap, control_rate);
  EXPECT_GE(flood_achieved, testing::requiredParam(private_nh, "min_flood_share") * flood_rate);
  EXPECT_GE(status_rate, testing::requiredParam(private_nh, "min_rate_share") * control_rate);
  EXPECT_LE(max_gap, testing::requiredParam(private_nh, "max_status_gap"));
  const std::lock_guard<std::mutex> lock(mutex);
  EXPECT_EQ(last.mode, FollowerStatus::MODE_TRACKING) << last.mode_name;
}

}  // namespace
}  // namespace projection_collision_avoidance
