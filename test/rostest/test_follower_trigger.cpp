/// rostest: a follower with ~trigger measurement (test/rostest/follower_trigger.test). Parameters
/// of the test node:
///   ~measurements         how many measurements to publish, one at a time, a period apart
///   ~control_rate         the follower's control rate (Hz)
///   ~measurement_timeout  the follower's ~measurement_timeout (s)
///   ~fallback_ticks       timer steps to see once the measurement is stale
///   ~max_tick_delay       s; bound on a measurement step's tick_delay (now - stamp at its start)
///   ~wall_deadline        wall seconds to wait for each condition
///   ~control_loop         the follower's ~control_loop ("timer" or "thread"), for its diagnostics

#include <algorithm>
#include <cstdint>
#include <string>
#include <vector>

#include <geometry_msgs/AccelStamped.h>
#include <gtest/gtest.h>
#include <ros/ros.h>

#include "projection_collision_avoidance/RelativeMeasurement.h"

#include "test_common.h"

namespace projection_collision_avoidance {
namespace {

using testing::StatusSample;

class FollowerTriggerTest : public testing::FollowerTest {
 protected:
  FollowerTriggerTest() {
    command_subscriber_ = nh_.subscribe("/follower/command", 1000, &FollowerTriggerTest::onCommand,
                                        this, ros::TransportHints().tcpNoDelay());
    status_subscriber_ = nh_.subscribe("/follower/status", 1000, &FollowerTriggerTest::onStatus,
                                       this, ros::TransportHints().tcpNoDelay());
    publisher_ = nh_.advertise<RelativeMeasurement>("/follower/relative_measurement", 100);
  }

  /// Waits until the follower hears this node and this node hears the follower, and then a
  /// control period, so that the first measurement of a test is a period after those of the
  /// test before (a measurement sooner is held).
  bool connected() {
    if (!waitFor(
            [this] {
              return publisher_.getNumSubscribers() > 0 &&
                     command_subscriber_.getNumPublishers() > 0 &&
                     status_subscriber_.getNumPublishers() > 0;
            },
            param("wall_deadline"))) {
      return false;
    }
    const ros::Time settled = ros::Time::now() + ros::Duration(1.0 / param("control_rate"));
    return waitFor([settled] { return ros::Time::now() >= settled; }, param("wall_deadline"));
  }

  /// Publishes one valid measurement stamped now; returns the stamp.
  ros::Time publishMeasurement() {
    const RelativeMeasurement msg = testing::measurementNow(5.5, 0.1);
    publisher_.publish(msg);
    return msg.header.stamp;
  }

  /// Whether a command stamped @p stamp has arrived (mutex_ held).
  bool commandArrived(const ros::Time& stamp) const {
    return std::find(commands_.begin(), commands_.end(), stamp) != commands_.end();
  }

  /// The status stamped @p stamp, or nullptr (mutex_ held).
  const StatusSample* statusAt(const ros::Time& stamp) const {
    for (const StatusSample& s : statuses_) {
      if (s.stamp == stamp) {
        return &s;
      }
    }
    return nullptr;
  }

  ros::Publisher publisher_;
  std::vector<ros::Time> commands_;  ///< header stamps of the commands, in arrival order
  std::vector<StatusSample> statuses_;

 private:
  void onCommand(const geometry_msgs::AccelStamped::ConstPtr& msg) {
    const std::lock_guard<std::mutex> lock(mutex_);
    commands_.push_back(msg->header.stamp);
  }

  void onStatus(const FollowerStatus::ConstPtr& msg) {
    const std::lock_guard<std::mutex> lock(mutex_);
    statuses_.push_back(testing::sampleOf(*msg));
  }

  ros::Subscriber command_subscriber_;
  ros::Subscriber status_subscriber_;
};

TEST_F(FollowerTriggerTest, EachMeasurementRunsOneStepStampedWithIt) {
  ASSERT_TRUE(connected()) << "the follower and the test never connected";
  const int n = static_cast<int>(param("measurements"));
  const double deadline = param("wall_deadline");
  const ros::Duration period(1.0 / param("control_rate"));
  std::vector<ros::Time> stamps;
  // One at a time: the next once the command answering this one (and its status) arrived, and a
  // control period after it (a measurement sooner would be held: doc/boundary.md, Time).
  for (int i = 0; i < n; ++i) {
    if (!stamps.empty()) {
      const ros::Time due = stamps.back() + period;
      ASSERT_TRUE(waitFor([due] { return ros::Time::now() >= due; }, deadline));
    }
    const ros::Time stamp = publishMeasurement();
    stamps.push_back(stamp);
    ASSERT_TRUE(waitFor(
        [this, stamp] { return commandArrived(stamp) && statusAt(stamp) != nullptr; }, deadline))
        << "no command or status stamped with measurement " << i;
  }
  const std::lock_guard<std::mutex> lock(mutex_);
  // Exactly one command per measurement, each with the measurement's stamp, none in between.
  std::vector<ros::Time> answered;
  for (const ros::Time& command : commands_) {
    if (command >= stamps.front() && command <= stamps.back()) {
      answered.push_back(command);
    }
  }
  EXPECT_EQ(answered, stamps);
  // status.ticks counts them: consecutive, one step per measurement (no timer step while fresh).
  const StatusSample* first = statusAt(stamps.front());
  const StatusSample* last = statusAt(stamps.back());
  ASSERT_NE(first, nullptr);
  ASSERT_NE(last, nullptr);
  EXPECT_EQ(last->ticks - first->ticks, static_cast<std::uint64_t>(n - 1));
  const double max_tick_delay = param("max_tick_delay");
  for (const ros::Time& stamp : stamps) {
    const StatusSample* s = statusAt(stamp);
    ASSERT_NE(s, nullptr);
    EXPECT_EQ(s->mode, FollowerStatus::MODE_TRACKING);
    EXPECT_GE(s->tick_delay, 0.0);
    EXPECT_LE(s->tick_delay, max_tick_delay);
  }
  // Every status since the first measurement answers one of them.
  for (const StatusSample& s : statuses_) {
    if (s.stamp >= stamps.front() && s.stamp <= stamps.back()) {
      EXPECT_TRUE(std::find(stamps.begin(), stamps.end(), s.stamp) != stamps.end())
          << "a step stamped " << s.stamp << " answers no measurement";
    }
  }
}

TEST_F(FollowerTriggerTest, StaleMeasurementBrakesOnTheTimerUntilTheNextOne) {
  ASSERT_TRUE(connected()) << "the follower and the test never connected";
  const double deadline = param("wall_deadline");
  const ros::Time stamp = publishMeasurement();
  ASSERT_TRUE(waitFor([this, stamp] { return statusAt(stamp) != nullptr; }, deadline));
  const std::uint64_t ticks = [this, stamp] {
    const std::lock_guard<std::mutex> lock(mutex_);
    return statusAt(stamp)->ticks;
  }();
  // Once older than measurement_timeout, the timer runs fallback steps, one per period.
  const auto fallback_ticks = static_cast<std::uint64_t>(param("fallback_ticks"));
  const double timeout = param("measurement_timeout");
  ASSERT_TRUE(waitFor(
      [this, ticks, fallback_ticks] {
        return !statuses_.empty() && statuses_.back().fallback &&
               statuses_.back().ticks >= ticks + fallback_ticks;
      },
      timeout + deadline))
      << "no braking on the timer after the measurement went stale";
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    const StatusSample& s = statuses_.back();
    EXPECT_EQ(s.mode, FollowerStatus::MODE_MEASUREMENT_LOST);
    EXPECT_GT((s.stamp - stamp).toSec(), timeout);  // stamped by the timer, not a measurement
  }
  // The next measurement runs a tracking step at once, stamped with it.
  const ros::Time again = publishMeasurement();
  ASSERT_TRUE(waitFor([this, again] { return commandArrived(again) && statusAt(again) != nullptr; },
                      deadline));
  const std::lock_guard<std::mutex> lock(mutex_);
  EXPECT_EQ(statusAt(again)->mode, FollowerStatus::MODE_TRACKING);
  EXPECT_FALSE(statusAt(again)->fallback);
}

TEST_F(FollowerTriggerTest, DiagnosticsNameTheTriggerAndTheLoop) {
  ASSERT_TRUE(connected()) << "the follower and the test never connected";
  std::string loop;
  ASSERT_TRUE(private_nh_.getParam("control_loop", loop)) << "missing test parameter ~control_loop";
  const auto value = &testing::diagnosticValue;
  EXPECT_TRUE(waitFor(
      [&] {
        return std::any_of(follower_diagnostics_.begin(), follower_diagnostics_.end(),
                           [&](const diagnostic_msgs::DiagnosticStatus& status) {
                             return value(status, "trigger") == "measurement" &&
                                    value(status, "control_loop") == loop;
                           });
      },
      param("wall_deadline")))
      << "no diagnostics with trigger measurement and control_loop " << loop;
}

}  // namespace
}  // namespace projection_collision_avoidance
