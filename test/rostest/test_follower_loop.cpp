/// rostest: a follower with ~control_loop thread next to one with ~control_loop timer
/// (test/rostest/follower_loop.test). Both get the same constant measurement at ~measurement_rate
/// from this node for its whole run, so neither ever falls back and step n of one runs the same
/// laws on the same inputs as step n of the other. Parameters of the test node:
///   ~control_rate              the followers' control rate (Hz)
///   ~measurement_rate          Hz of the measurements published to both
///   ~ticks                     consecutive steps of the thread follower to observe
///   ~min_rate_ratio, ~max_rate_ratio  bounds on its steps per second / control_rate
///   ~accounting_slack_periods  |steps + missed - deadlines passed| at most this
///   ~min_common_ticks          step numbers both followers must have reported
///   ~command_tolerance         m/s^2, |command of the thread - of the timer| at one step number
///   ~wall_deadline             wall seconds to wait for each condition

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include <geometry_msgs/AccelStamped.h>
#include <gtest/gtest.h>
#include <ros/callback_queue.h>
#include <ros/ros.h>

#include "projection_collision_avoidance/RelativeMeasurement.h"

#include "test_common.h"

namespace projection_collision_avoidance {
namespace {

/// Publishes the same valid measurement (stamped now) to both followers at a fixed rate, from a
/// queue and thread of its own, for the whole test process.
class MeasurementSource {
 public:
  explicit MeasurementSource(double rate) {
    nh_.setCallbackQueue(&queue_);
    for (const char* topic :
         {"/follower/relative_measurement", "/follower_timer/relative_measurement"}) {
      publishers_.push_back(nh_.advertise<RelativeMeasurement>(topic, 10));
    }
    timer_ = nh_.createWallTimer(ros::WallDuration(1.0 / rate),
                                 [this](const ros::WallTimerEvent& /*event*/) { publish(); });
    spinner_.start();
  }

  ~MeasurementSource() {
    timer_.stop();
    spinner_.stop();
  }

  MeasurementSource(const MeasurementSource&) = delete;
  MeasurementSource& operator=(const MeasurementSource&) = delete;

  /// Whether both followers subscribe.
  bool heard() const {
    return std::all_of(publishers_.begin(), publishers_.end(),
                       [](const ros::Publisher& p) { return p.getNumSubscribers() > 0; });
  }

 private:
  void publish() {
    const RelativeMeasurement msg = testing::measurementNow(5.5, 0.1);
    for (const ros::Publisher& publisher : publishers_) {
      publisher.publish(msg);
    }
  }

  ros::CallbackQueue queue_;
  ros::NodeHandle nh_;
  std::vector<ros::Publisher> publishers_;
  ros::WallTimer timer_;
  ros::AsyncSpinner spinner_{1, &queue_};
};

std::unique_ptr<MeasurementSource> g_source;

/// Starts the measurement source once ros::init has run (rostest_main.cpp) and before the
/// first test, and stops it after the last: a gap between the tests would put the followers in
/// the fallback at different steps. Without a positive ~measurement_rate no test runs.
class MeasurementSourceEnvironment : public ::testing::Environment {
 public:
  void SetUp() override {
    ros::NodeHandle private_nh("~");
    double rate = 0.0;
    if (!private_nh.getParam("measurement_rate", rate) || !(rate > 0.0)) {
      ROS_FATAL("test_follower_loop: ~measurement_rate missing or not positive");
      GTEST_FAIL() << "~measurement_rate missing or not positive";
    }
    g_source = std::make_unique<MeasurementSource>(rate);
  }

  void TearDown() override { g_source.reset(); }
};

// gtest owns the environment.
::testing::Environment* const g_source_environment =
    ::testing::AddGlobalTestEnvironment(new MeasurementSourceEnvironment);

using testing::sampleOf;
using testing::StatusSample;

class FollowerLoopTest : public testing::FollowerTest {
 protected:
  FollowerLoopTest() {
    const ros::TransportHints hints = ros::TransportHints().tcpNoDelay();
    thread_status_ = nh_.subscribe<FollowerStatus>(
        "/follower/status", 1000,
        [this](const FollowerStatus::ConstPtr& msg) { add(&thread_statuses_, *msg); }, nullptr,
        hints);
    timer_status_ = nh_.subscribe<FollowerStatus>(
        "/follower_timer/status", 1000,
        [this](const FollowerStatus::ConstPtr& msg) { add(&timer_statuses_, *msg); }, nullptr,
        hints);
    command_subscriber_ = nh_.subscribe<geometry_msgs::AccelStamped>(
        "/follower/command", 1000,
        [this](const geometry_msgs::AccelStamped::ConstPtr& msg) {
          const std::lock_guard<std::mutex> lock(mutex_);
          commands_.push_back(msg->header.stamp);
        },
        nullptr, hints);
  }

  /// Waits until both followers hear the measurements and this node hears both.
  bool connected() {
    return waitFor(
        [this] {
          return g_source->heard() && thread_status_.getNumPublishers() > 0 &&
                 timer_status_.getNumPublishers() > 0 && command_subscriber_.getNumPublishers() > 0;
        },
        param("wall_deadline"));
  }

  std::vector<StatusSample> thread_statuses_;
  std::vector<StatusSample> timer_statuses_;
  std::vector<ros::Time> commands_;  ///< stamps of the thread follower's commands

 private:
  void add(std::vector<StatusSample>* samples, const FollowerStatus& msg) {
    const std::lock_guard<std::mutex> lock(mutex_);
    samples->push_back(sampleOf(msg));
  }

  ros::Subscriber thread_status_;
  ros::Subscriber timer_status_;
  ros::Subscriber command_subscriber_;
};

TEST_F(FollowerLoopTest, ThreadTicksAtItsRateAndAccountsForEveryDeadline) {
  ASSERT_TRUE(connected()) << "the followers and the test never connected";
  const auto wanted = static_cast<std::size_t>(param("ticks"));
  ASSERT_TRUE(
      waitFor([this, wanted] { return thread_statuses_.size() > wanted; }, param("wall_deadline")))
      << "the thread follower reported fewer than " << wanted << " steps";
  const double rate = param("control_rate");
  const double period = 1.0 / rate;
  const std::lock_guard<std::mutex> lock(mutex_);
  const std::vector<StatusSample>& s = thread_statuses_;
  const StatusSample& a = s.front();
  const StatusSample& b = s.back();
  // One status per step, none lost: the step count goes up by one each time.
  for (std::size_t i = 1; i < s.size(); ++i) {
    ASSERT_EQ(s[i].ticks, s[i - 1].ticks + 1) << "status " << i;
  }
  const auto steps = static_cast<double>(b.ticks - a.ticks);
  const double span = (b.stamp - a.stamp).toSec();
  ASSERT_GT(span, 0.0);
  // At its rate.
  EXPECT_GE(steps / span, param("min_rate_ratio") * rate);
  EXPECT_LE(steps / span, param("max_rate_ratio") * rate);
  // Every deadline between a and b (the stamp minus the tick delay) is a step or missed.
  const double deadlines =
      std::round(((b.stamp.toSec() - b.tick_delay) - (a.stamp.toSec() - a.tick_delay)) * rate);
  const double missed = static_cast<double>(b.missed_periods - a.missed_periods);
  EXPECT_LE(std::abs(steps + missed - deadlines), param("accounting_slack_periods"))
      << steps << " steps and " << missed << " missed periods over " << deadlines << " deadlines";
  // Late periods: the steps whose tick delay exceeds half a period; never woken early.
  std::uint32_t late = 0;
  for (std::size_t i = 1; i < s.size(); ++i) {
    late += s[i].tick_delay > 0.5 * period ? 1 : 0;
  }
  EXPECT_EQ(b.late_periods - a.late_periods, late);
  for (const StatusSample& sample : s) {
    EXPECT_GE(sample.tick_delay, 0.0);
    EXPECT_EQ(sample.mode, FollowerStatus::MODE_TRACKING);
  }
  // One command per step, from the first command heard (its subscription may have connected
  // after the status one).
  ASSERT_FALSE(commands_.empty());
  const ros::Time from = std::max(a.stamp, commands_.front());
  const auto in_window = [&](const ros::Time& t) { return t >= from && t <= b.stamp; };
  EXPECT_EQ(std::count_if(commands_.begin(), commands_.end(), in_window),
            std::count_if(s.begin(), s.end(),
                          [&](const StatusSample& sample) { return in_window(sample.stamp); }));
}

TEST_F(FollowerLoopTest, SameCommandsAsTheTimerLoopAtEveryStep) {
  ASSERT_TRUE(connected()) << "the followers and the test never connected";
  const auto wanted = static_cast<std::size_t>(param("min_common_ticks"));
  // Step numbers both reported, thread statuses by step number.
  const auto common = [this] {
    std::map<std::uint64_t, const StatusSample*> by_tick;
    for (const StatusSample& s : timer_statuses_) {
      by_tick[s.ticks] = &s;
    }
    std::vector<std::pair<const StatusSample*, const StatusSample*>> pairs;
    for (const StatusSample& s : thread_statuses_) {
      const auto it = by_tick.find(s.ticks);
      if (it != by_tick.end()) {
        pairs.emplace_back(&s, it->second);
      }
    }
    return pairs;
  };
  ASSERT_TRUE(waitFor([&] { return common().size() >= wanted; }, param("wall_deadline")))
      << "fewer than " << wanted << " step numbers reported by both followers";
  const double tolerance = param("command_tolerance");
  const std::lock_guard<std::mutex> lock(mutex_);
  double lowest = INFINITY;
  double highest = -INFINITY;
  int mismatches = 0;
  for (const auto& pair : common()) {
    const StatusSample& thread = *pair.first;
    const StatusSample& timer = *pair.second;
    ASSERT_EQ(thread.mode, FollowerStatus::MODE_TRACKING) << "step " << thread.ticks;
    ASSERT_EQ(timer.mode, FollowerStatus::MODE_TRACKING) << "step " << timer.ticks;
    ASSERT_EQ(thread.command.size(), 1U);
    ASSERT_EQ(timer.command.size(), 1U);
    if (!(std::abs(thread.command[0] - timer.command[0]) <= tolerance) && ++mismatches <= 5) {
      ADD_FAILURE() << "step " << thread.ticks << ": thread command " << thread.command[0]
                    << ", timer command " << timer.command[0];
    }
    lowest = std::min(lowest, thread.command[0]);
    highest = std::max(highest, thread.command[0]);
  }
  EXPECT_EQ(mismatches, 0) << "of " << common().size() << " steps";
  // The command changes from step to step, so a step number off by one would show.
  EXPECT_GT(highest - lowest, 1000.0 * tolerance);
}

TEST_F(FollowerLoopTest, DiagnosticsNameTheLoop) {
  ASSERT_TRUE(connected()) << "the followers and the test never connected";
  const auto value = &testing::diagnosticValue;
  const auto reported = [&](const std::string& node, const std::string& loop) {
    return std::any_of(follower_diagnostics_.begin(), follower_diagnostics_.end(),
                       [&](const diagnostic_msgs::DiagnosticStatus& status) {
                         return status.name.rfind(node + ": ", 0) == 0 &&
                                value(status, "control_loop") == loop &&
                                value(status, "ticks") != "0" &&
                                value(status, "missed_periods") != "(missing)";
                       });
  };
  EXPECT_TRUE(
      waitFor([&] { return reported("follower/controller", "thread"); }, param("wall_deadline")));
  EXPECT_TRUE(waitFor([&] { return reported("follower_timer/controller", "timer"); },
                      param("wall_deadline")));
}

}  // namespace
}  // namespace projection_collision_avoidance
