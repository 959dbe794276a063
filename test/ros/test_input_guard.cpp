/// The admission of input messages (InputGuard, admitGuarded, TimeJumpWatch and InputTimeline
/// on ROS time): no master needed.

#include <cmath>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <string>

#include <gtest/gtest.h>

#include "projection_collision_avoidance/cycle/InputGuard.hpp"
#include "projection_collision_avoidance/ros/InputAdmission.hpp"

namespace projection_collision_avoidance {
namespace {

constexpr std::int64_t kSecond = 1000000000;
/// The largest ros::Time: 2^32 - 1 s and 999999999 ns.
constexpr std::int64_t kLatest = 4294967295LL * kSecond + 999999999LL;

/// A clock the tests move by hand.
InputGuard::Clock::time_point fake_now;
InputGuard::Clock::time_point fakeClock() { return fake_now; }

InputGuard makeGuard(double max_future = 0.1, double max_age = 0.5, std::string frame = "") {
  return InputGuard("input", {std::move(frame), max_future, max_age}, &fakeClock);
}

TEST(InputGuard, RefusesZeroFutureStaleOutOfOrderAndRepeatedStamps) {
  InputGuard guard = makeGuard();
  const std::int64_t now = 100 * kSecond;
  EXPECT_FALSE(guard.checkHeader("", 0, now));
  EXPECT_EQ(guard.lastRejection().rfind("zero stamp", 0), 0U) << guard.lastRejection();
  EXPECT_FALSE(guard.checkHeader("", now + kSecond / 5, now));  // 0.2 s ahead, 0.1 allowed
  EXPECT_EQ(guard.lastRejection().rfind("future stamp", 0), 0U);
  EXPECT_FALSE(guard.checkHeader("", now - kSecond, now));  // 1 s old, 0.5 allowed
  EXPECT_EQ(guard.lastRejection().rfind("stale", 0), 0U);
  ASSERT_TRUE(guard.checkHeader("", now - kSecond / 10, now));
  guard.accept(now - kSecond / 10, now);
  EXPECT_FALSE(guard.checkHeader("", now - kSecond / 10, now));
  EXPECT_EQ(guard.lastRejection().rfind("repeated stamp", 0), 0U);
  EXPECT_FALSE(guard.checkHeader("", now - kSecond / 5, now));
  EXPECT_EQ(guard.lastRejection().rfind("out of order", 0), 0U);
  EXPECT_TRUE(guard.checkHeader("", now + kSecond / 20, now));  // 50 ms ahead: allowed
  EXPECT_EQ(guard.rejected(), 5U);
}

TEST(InputGuard, AFrameMatchesUpToALeadingSlash) {
  // "/robot_0/odom" (a ROS 1 driver's spelling) and "robot_0/odom" (tf2's) name one frame.
  const std::int64_t now = 100 * kSecond;
  InputGuard guard = makeGuard(0.1, 0.5, "robot_0/odom");
  EXPECT_TRUE(guard.checkHeader("/robot_0/odom", now, now));
  InputGuard slashed = makeGuard(0.1, 0.5, "/robot_0/odom");
  EXPECT_TRUE(slashed.checkHeader("robot_0/odom", now, now));
  EXPECT_TRUE(slashed.checkHeader("/robot_0/odom", now, now));
  EXPECT_FALSE(slashed.checkHeader("robot_1/odom", now, now));
  EXPECT_FALSE(slashed.checkHeader("//robot_0/odom", now, now));  // tf2 strips one slash only
  EXPECT_FALSE(slashed.checkHeader("", now, now));
  EXPECT_EQ(slashed.rejected(), 3U);
}

TEST(InputGuard, JudgesStampsOverTheWholeRangeOfRosTime) {
  for (const std::int64_t now : {std::int64_t{1}, 1700000000 * kSecond, kLatest}) {
    for (const std::int64_t stamp :
         {std::int64_t{1}, kSecond, 1700000000 * kSecond, kLatest - 1, kLatest}) {
      for (const double max_age : {0.0, 0.5}) {
        InputGuard guard = makeGuard(0.1, max_age);
        const bool ahead = stamp - now > kSecond / 10;
        const bool stale = max_age > 0.0 && now - stamp > kSecond / 2;
        EXPECT_EQ(guard.checkHeader("", stamp, now), !ahead && !stale)
            << "stamp " << stamp << " now " << now << " max_age " << max_age;
        if (!ahead && !stale) {
          guard.accept(stamp, now);
          EXPECT_GE(guard.ageAt(now), 0.0);
          EXPECT_TRUE(std::isfinite(guard.ageAt(now)));
        }
      }
    }
  }
}

TEST(InputGuard, AgesCountFromReceiptForStampsAheadAndAreNeverNegative) {
  InputGuard guard = makeGuard();
  const std::int64_t now = 50 * kSecond;
  guard.accept(now + kSecond / 20, now);  // 50 ms ahead of the receiver's clock
  EXPECT_DOUBLE_EQ(guard.ageAt(now), 0.0);
  EXPECT_DOUBLE_EQ(guard.ageAt(now + kSecond / 10), 0.1);
  EXPECT_EQ(guard.lastStamp(), now + kSecond / 20);  // the order check keeps the real stamp
}

TEST(InputGuard, RestartingTheTimelineForgetsTheOldOne) {
  InputGuard guard = makeGuard();
  guard.accept(80 * kSecond, 80 * kSecond);
  guard.restartTimeline();
  EXPECT_FALSE(guard.haveAccepted());
  EXPECT_TRUE(guard.everAccepted());
  EXPECT_TRUE(std::isinf(guard.ageAt(10 * kSecond)));
  EXPECT_TRUE(guard.checkHeader("", 10 * kSecond, 10 * kSecond));  // earlier than before: fine
}

TEST(InputGuard, LogsOncePerChangeOfKindWithCounts) {
  fake_now = InputGuard::Clock::time_point{};
  InputGuard guard = makeGuard(0.1, 0.5, "world");
  const std::int64_t now = 100 * kSecond;
  // A thousand refusals of one kind, with accepted messages between them: one line.
  int lines = 0;
  for (int i = 1; i <= 1000; ++i) {
    EXPECT_FALSE(guard.checkHeader("other", now, now));
    lines += guard.takeLogLine().empty() ? 0 : 1;
    guard.accept(now + i, now + i);
  }
  EXPECT_EQ(lines, 1);
  EXPECT_EQ(guard.rejectedOfKind(), 1000U);
  // Another kind within the transition period: folded into the next line.
  EXPECT_FALSE(guard.checkHeader("world", 0, now));
  EXPECT_TRUE(guard.takeLogLine().empty());
  fake_now += InputGuard::kTransitionPeriod;
  EXPECT_FALSE(guard.checkHeader("world", 0, now));
  const std::string line = guard.takeLogLine();
  EXPECT_NE(line.find("zero stamp"), std::string::npos) << line;
  EXPECT_NE(line.find("1001 refusals since the last line, 1002 in all"), std::string::npos) << line;
  // The same kind goes on: a summary once per summary period.
  for (int i = 0; i < 100; ++i) {
    EXPECT_FALSE(guard.checkHeader("world", 0, now));
    EXPECT_TRUE(guard.takeLogLine().empty());
  }
  fake_now += InputGuard::kSummaryPeriod;
  EXPECT_FALSE(guard.checkHeader("world", 0, now));
  EXPECT_NE(guard.takeLogLine().find("101 refusals since the last line"), std::string::npos);
}

TEST(InputGuard, TextsFromSendersAreBounded) {
  InputGuard guard = makeGuard(0.1, 0.5, "world");
  const std::string huge(1 << 20, 'x');
  EXPECT_FALSE(guard.checkHeader(huge, kSecond, kSecond));
  EXPECT_LT(guard.lastRejection().size(), 200U);
  EXPECT_NE(guard.lastRejection().find("(1048576 bytes)"), std::string::npos);
  guard.reject(Rejection::kContent, huge);  // e.g. an exception's text
  EXPECT_LT(guard.lastRejection().size(), InputGuard::kMaxReasonLength + 40);
  EXPECT_LT(guard.takeLogLine().size(), 500U);
}

TEST(AdmitGuarded, AMessageThatCannotBeJudgedIsCountedNotFatal) {
  InputGuard guard = makeGuard();
  admitGuarded(guard, "test",
               [] { throw std::runtime_error("Duration is out of dual 32-bit range"); });
  admitGuarded(guard, "test", [] { throw 42; });
  EXPECT_EQ(guard.rejected(), 2U);
  EXPECT_EQ(guard.lastRejection().rfind("unjudgeable", 0), 0U);
  int ran = 0;
  admitGuarded(guard, "test", [&] { ++ran; });
  EXPECT_EQ(ran, 1);
  EXPECT_EQ(guard.rejected(), 2U);
}

TEST(TimeJumpWatch, ReportsEachJumpBackOfRosTimeOnce) {
  TimeJumpWatch watch;
  EXPECT_FALSE(wentBack(watch, ros::Time(10.0)));
  EXPECT_FALSE(wentBack(watch, ros::Time(10.0)));  // standing still is no jump
  EXPECT_FALSE(wentBack(watch, ros::Time(11.0)));
  EXPECT_TRUE(wentBack(watch, ros::Time(2.0)));
  EXPECT_DOUBLE_EQ(watch.jump(), -9.0);
  EXPECT_FALSE(wentBack(watch, ros::Time(2.5)));
  EXPECT_TRUE(wentBack(watch, ros::Time(0, 1)));
  EXPECT_EQ(watch.jumps(), 2U);
  EXPECT_DOUBLE_EQ(secondsBetween(ros::Time(4294967295U, 999999999U), ros::Time(0, 1)),
                   4294967295.999999998);
}

TEST(InputTimeline, JudgesRosHeadersAndCountsWhatCannotBeJudged) {
  InputTimelineOptions options;
  options.limits = {"world", 0.05, 0.5};
  InputTimeline timeline("topic", options);
  std_msgs::Header header;
  header.frame_id = "world";
  header.stamp = ros::Time(100.0);
  admitGuarded(timeline, "test", [&] {
    ASSERT_TRUE(checkHeader(timeline, header, ros::Time(100.01)));
    timeline.accept();
  });
  EXPECT_NEAR(timeline.age(nanosecondsOf(ros::Time(100.02))), 0.02, 1e-9);
  admitGuarded(timeline, "test", [] { throw std::runtime_error("no"); });
  EXPECT_EQ(timeline.rejected(), 1U);
  EXPECT_EQ(timeline.guard().lastKind(), Rejection::kUnjudgeable);
  // ROS time went back: the timeline restarts, the input has no age until the next one.
  header.stamp = ros::Time(5.0);
  EXPECT_TRUE(checkHeader(timeline, header, ros::Time(5.0)));
  EXPECT_EQ(timeline.age(nanosecondsOf(ros::Time(5.0))), kNoInputAge);
  EXPECT_EQ(timeline.jumps().jumps(), 1U);
}

}  // namespace
}  // namespace projection_collision_avoidance
