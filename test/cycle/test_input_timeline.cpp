// InputTimeline: one input's admission (verdicts), its stamps on this clock, jumps back of the
// receiver's clock and its age; TimeJumpWatch. No master.
#include <chrono>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>

#include <gtest/gtest.h>

#include "projection_collision_avoidance/cycle/InputTimeline.hpp"
#include "projection_collision_avoidance/cycle/TimeJumpWatch.hpp"

namespace projection_collision_avoidance {
namespace {

constexpr std::int64_t kSecond = 1000000000;
constexpr std::int64_t kMs = 1000000;
constexpr std::int64_t kT0 = 1000 * kSecond;

InputTimelineOptions optionsOf(ClockPolicy policy = ClockPolicy::kStamps) {
  InputTimelineOptions o;
  o.limits = {"world", 0.1, 0.5};  // frame, max_future_stamp, max_age
  o.correction.policy = policy;
  return o;
}

TEST(TimeJumpWatch, ReportsEachJumpBackOnce) {
  TimeJumpWatch watch;
  EXPECT_FALSE(watch.wentBack(10 * kSecond));
  EXPECT_FALSE(watch.wentBack(10 * kSecond));  // standing still is no jump
  EXPECT_FALSE(watch.wentBack(11 * kSecond));
  EXPECT_EQ(watch.latest(), 11 * kSecond);
  EXPECT_TRUE(watch.wentBack(2 * kSecond));
  EXPECT_DOUBLE_EQ(watch.jump(), -9.0);
  EXPECT_FALSE(watch.wentBack(2 * kSecond + 500 * kMs));
  EXPECT_EQ(watch.jump(), 0.0);
  EXPECT_TRUE(watch.wentBack(1));
  EXPECT_EQ(watch.jumps(), 2u);
}

TEST(InputTimeline, JudgesHeadersAsItsGuard) {
  InputTimeline t("topic", optionsOf());
  EXPECT_FALSE(t.checkHeader("map", kT0, kT0));
  EXPECT_EQ(t.guard().lastKind(), Rejection::kFrame);
  EXPECT_FALSE(t.checkHeader("world", 0, kT0));
  EXPECT_EQ(t.guard().lastKind(), Rejection::kZeroStamp);
  EXPECT_FALSE(t.checkHeader("world", kT0 + 200 * kMs, kT0));
  EXPECT_EQ(t.guard().lastKind(), Rejection::kFuture);
  EXPECT_FALSE(t.checkHeader("world", kT0 - 600 * kMs, kT0));
  EXPECT_EQ(t.guard().lastKind(), Rejection::kStale);
  EXPECT_EQ(t.rejected(), 4u);
  EXPECT_FALSE(t.takeLogLine().empty());

  ASSERT_TRUE(t.checkHeader("world", kT0 - 10 * kMs, kT0));
  EXPECT_EQ(t.accept(), kT0 - 10 * kMs);
  EXPECT_FALSE(t.checkHeader("world", kT0 - 10 * kMs, kT0 + kMs));
  EXPECT_EQ(t.guard().lastKind(), Rejection::kRepeated);
  EXPECT_FALSE(t.checkHeader("world", kT0 - 20 * kMs, kT0 + kMs));
  EXPECT_EQ(t.guard().lastKind(), Rejection::kOutOfOrder);
  ASSERT_TRUE(t.checkHeader("world", kT0, kT0 + 2 * kMs));
  t.reject(Rejection::kContent, "non-finite");
  EXPECT_EQ(t.rejected(), 7u);
  EXPECT_EQ(t.guard().accepted(), 1u);
  EXPECT_EQ(t.guard().lastRejection(), "content: non-finite");
}

TEST(InputTimeline, AgeIsInfiniteWithoutInputAndCountsFromTheEarlierOfStampAndReceipt) {
  InputTimeline t("topic", optionsOf());
  EXPECT_EQ(t.age(kT0), kNoInputAge);
  EXPECT_TRUE(std::isinf(t.age(kT0)) && t.age(kT0) > 0.0);
  EXPECT_EQ(t.receipt(), InputTimeline::kNone);

  ASSERT_TRUE(t.checkHeader("world", kT0 - 30 * kMs, kT0));
  t.accept();
  EXPECT_EQ(t.receipt(), kT0);
  EXPECT_NEAR(t.age(kT0), 0.030, 1e-12);
  EXPECT_NEAR(t.age(kT0 + 100 * kMs), 0.130, 1e-12);
  EXPECT_NEAR(t.skew(), 0.030, 1e-12);
  EXPECT_EQ(t.age(kT0 - kMs), kNoInputAge);  // received after then: of another timeline

  // Stamped ahead (within max_future_stamp): counts from its receipt.
  ASSERT_TRUE(t.checkHeader("world", kT0 + 60 * kMs, kT0 + 10 * kMs));
  t.accept();
  EXPECT_NEAR(t.age(kT0 + 10 * kMs), 0.0, 1e-12);
  EXPECT_NEAR(t.age(kT0 + 30 * kMs), 0.020, 1e-12);
  // The one age function.
  EXPECT_EQ(t.age(kT0 + 30 * kMs), inputAge(kT0 + 30 * kMs, t.stamp(), t.receipt()));
}

TEST(InputTimeline, AJumpBackRestartsTheTimeline) {
  InputTimeline t("topic", optionsOf());
  ASSERT_TRUE(t.checkHeader("world", kT0, kT0 + kMs));
  t.accept();
  // ROS time restarts 100 s earlier: the old input is forgotten, a new one is not out of order.
  ASSERT_TRUE(t.checkHeader("world", kT0 - 100 * kSecond, kT0 - 100 * kSecond));
  EXPECT_EQ(t.jumps().jumps(), 1u);
  EXPECT_NEAR(t.jumps().jump(), -100.001, 1e-9);
  EXPECT_EQ(t.age(kT0 - 100 * kSecond), kNoInputAge);
  EXPECT_FALSE(t.guard().haveAccepted());
  EXPECT_TRUE(t.guard().everAccepted());
  EXPECT_EQ(t.accept(), kT0 - 100 * kSecond);
  EXPECT_NEAR(t.age(kT0 - 100 * kSecond + 5 * kMs), 0.005, 1e-12);
  EXPECT_EQ(t.guard().accepted(), 2u);

  // noteTime() reports a jump once, and checkHeader() at the same time sees none.
  EXPECT_TRUE(t.noteTime(kT0 - 200 * kSecond));
  EXPECT_FALSE(t.checkHeader("world", kT0 - 300 * kSecond, kT0 - 200 * kSecond));  // stale
  EXPECT_EQ(t.jumps().jumps(), 2u);
}

TEST(InputTimeline, WithoutWatchingTimeOnlyRestartForgets) {
  InputTimelineOptions o = optionsOf();
  o.watch_time = false;
  InputTimeline t("topic", o);
  ASSERT_TRUE(t.checkHeader("world", kT0, kT0));
  t.accept();
  EXPECT_FALSE(t.checkHeader("world", kT0 - 10 * kSecond, kT0 - 10 * kSecond));
  EXPECT_EQ(t.guard().lastKind(), Rejection::kOutOfOrder);
  EXPECT_EQ(t.jumps().jumps(), 0u);
  t.restart();
  EXPECT_TRUE(t.checkHeader("world", kT0 - 10 * kSecond, kT0 - 10 * kSecond));
}

TEST(InputTimeline, ReceiptPolicyStampsAtReceiptAndKeepsStampsMonotone) {
  InputTimeline t("topic", optionsOf(ClockPolicy::kReceipt));
  // A sender 2 s ahead: judged at its own clock, put on this one.
  ASSERT_TRUE(t.checkHeader("world", kT0 + 2 * kSecond, kT0));
  EXPECT_EQ(t.offset(), -2 * kSecond);
  EXPECT_EQ(t.accept(), kT0);
  EXPECT_NEAR(t.age(kT0), 0.0, 1e-12);
  EXPECT_NEAR(t.skew(), -2.0, 1e-12);
  // This clock stands still (simulated time): the next stamp still lies after the last one.
  ASSERT_TRUE(t.checkHeader("world", kT0 + 2 * kSecond + kMs, kT0));
  EXPECT_EQ(t.accept(), kT0 + 1);
}

TEST(InputTimeline, AMessageWithoutHeaderIsStampedAtItsReceipt) {
  InputTimeline t("cmd_vel", optionsOf());
  EXPECT_EQ(t.age(kT0), kNoInputAge);
  t.checkReceipt(kT0);
  EXPECT_EQ(t.accept(), kT0);
  EXPECT_EQ(t.receipt(), kT0);
  EXPECT_NEAR(t.age(kT0 + 20 * kMs), 0.020, 1e-12);
  // Received at the same time (simulated time standing still): accepted, its stamp after the one
  // before; a content refusal counts.
  t.checkReceipt(kT0);
  EXPECT_EQ(t.accept(), kT0 + 1);
  t.checkReceipt(kT0);
  t.reject(Rejection::kContent, "non-finite field");
  EXPECT_EQ(t.rejected(), 1u);
  EXPECT_EQ(t.guard().accepted(), 2u);
  // Time going back restarts the timeline: no age until the next message.
  t.checkReceipt(kT0 - 10 * kSecond);
  EXPECT_EQ(t.jumps().jumps(), 1u);
  EXPECT_EQ(t.age(kT0 - 10 * kSecond), kNoInputAge);
  EXPECT_EQ(t.accept(), kT0 - 10 * kSecond);
}

TEST(InputTimeline, EstimatedOffsetCorrectsStampsAndNeverGoesBack) {
  InputTimelineOptions o = optionsOf(ClockPolicy::kEstimate);
  o.correction.max_drift_rate = 1.0;  // the offset may move as fast as the clock: no bound here
  InputTimeline t("topic", o);
  const std::int64_t behind = 2 * kSecond;  // the sender's clock is 2 s behind
  // Delay 10 ms: the first offset is the message's own skew.
  ASSERT_TRUE(t.checkHeader("world", kT0 - behind - 10 * kMs, kT0));
  EXPECT_EQ(t.offset(), behind + 10 * kMs);
  EXPECT_EQ(t.accept(), kT0);
  // Delay 3 ms: corrected with the window's smallest skew so far (2.010 s), 7 ms ahead.
  ASSERT_TRUE(t.checkHeader("world", kT0 - behind - 2 * kMs, kT0 + kMs));
  EXPECT_EQ(t.offset(), behind + 10 * kMs);
  EXPECT_EQ(t.accept(), kT0 + 8 * kMs);
  EXPECT_NEAR(t.skew(), 2.003, 1e-12);
  // The window's minimum is 2.003 s; the offset moves towards it by at most 1 s/s × 3 ms, to
  // 2.007 s: stamp + offset (kT0 + 7 ms) would lie before the stamp accepted before, so the
  // stamp is 1 ns after it.
  ASSERT_TRUE(t.checkHeader("world", kT0 - behind, kT0 + 4 * kMs));
  EXPECT_EQ(t.offset(), behind + 7 * kMs);
  EXPECT_EQ(t.accept(), kT0 + 8 * kMs + 1);
  // Stamped after its receipt: its age counts from the receipt.
  EXPECT_NEAR(t.age(kT0 + 10 * kMs), 0.006, 1e-9);
}

/// A clock of the log intervals the tests move by hand.
InputGuard::Clock::time_point log_now;
InputGuard::Clock::time_point logClock() { return log_now; }

/// A state stream's timeline: older stamps superseded, not refused.
InputTimeline stateTimeline() {
  InputTimelineOptions o = optionsOf();
  o.limits.max_future_stamp = 0.25;
  o.limits.supersede_older = true;
  return InputTimeline("odom", o, &logClock);
}

TEST(InputTimeline, AnOlderOrEqualStateIsSupersededNotRefused) {
  log_now = InputGuard::Clock::time_point{};
  InputTimeline t = stateTimeline();
  ASSERT_TRUE(t.checkHeader("world", kT0, kT0));
  t.accept();
  EXPECT_FALSE(t.checkHeader("world", kT0 - 10 * kMs, kT0 + kMs));  // reordered
  EXPECT_TRUE(t.guard().lastSuperseded());
  EXPECT_FALSE(t.takeLogLine().empty());                     // the first is logged
  EXPECT_FALSE(t.checkHeader("world", kT0, kT0 + 2 * kMs));  // one stamp twice (bursty clock)
  EXPECT_TRUE(t.guard().lastSuperseded());
  EXPECT_TRUE(t.takeLogLine().empty());
  EXPECT_EQ(t.rejected(), 0u);
  EXPECT_EQ(t.superseded(), 2u);
  EXPECT_EQ(t.guard().lastRejection(), "");
  // The age is the latest accepted one's; a newer stamp is accepted.
  EXPECT_NEAR(t.age(kT0 + 2 * kMs), 0.002, 1e-12);
  ASSERT_TRUE(t.checkHeader("world", kT0 + 10 * kMs, kT0 + 10 * kMs));
  EXPECT_FALSE(t.guard().lastSuperseded());
  t.accept();
  // The other checks come first: a stale or zero stamp is still a refusal.
  EXPECT_FALSE(t.checkHeader("world", 0, kT0 + 20 * kMs));
  EXPECT_FALSE(t.guard().lastSuperseded());
  EXPECT_EQ(t.guard().lastKind(), Rejection::kZeroStamp);
  EXPECT_EQ(t.rejected(), 1u);
  EXPECT_EQ(t.superseded(), 2u);
}

TEST(InputTimeline, AShuffledFloodOfStatesWritesAtMostOneLinePerSummaryPeriod) {
  log_now = InputGuard::Clock::time_point{};
  InputTimeline t = stateTimeline();
  // 2000 states 10 ms apart, each pair of neighbours swapped (as two publishing threads do),
  // and every tenth sent twice (a clock standing still between physics steps).
  int lines = 0;
  std::uint64_t accepted = 0;
  std::uint64_t sent = 0;
  for (int i = 0; i < 2000; i += 2) {
    const bool twice = i % 20 == 0;
    for (const int k : {i + 1, i, twice ? i + 1 : -1}) {
      if (k < 0) {
        continue;
      }
      ++sent;
      if (t.checkHeader("world", kT0 + k * 10 * kMs, kT0 + (i + 1) * 10 * kMs + kMs)) {
        t.accept();
        ++accepted;
      }
      lines += t.takeLogLine().empty() ? 0 : 1;
    }
    log_now += std::chrono::milliseconds(20);
  }
  // 20 s of steady time: the first line and none after (the summary period is 60 s).
  EXPECT_EQ(lines, 1);
  EXPECT_EQ(t.rejected(), 0u);
  EXPECT_EQ(accepted, 1000u);
  EXPECT_EQ(sent, 2100u);
  EXPECT_EQ(t.superseded(), 1100u);
  log_now += InputGuard::kSummaryPeriod;
  EXPECT_FALSE(t.checkHeader("world", kT0 + 19980 * kMs, kT0 + 20 * kSecond));
  EXPECT_TRUE(t.guard().lastSuperseded());
  const std::string line = t.takeLogLine();
  EXPECT_NE(line.find("1100 messages"), std::string::npos) << line;
}

TEST(InputTimeline, AStateAheadOfTheClockSupersedesForAtMostMaxFutureStamp) {
  InputTimeline t = stateTimeline();
  // Stamped one 100 ms physics step ahead of this clock (its /clock lags by one burst).
  ASSERT_TRUE(t.checkHeader("world", kT0 + 100 * kMs, kT0));
  t.accept();
  EXPECT_FALSE(t.checkHeader("world", kT0 + 50 * kMs, kT0 + 60 * kMs));
  EXPECT_TRUE(t.guard().lastSuperseded());
  ASSERT_TRUE(t.checkHeader("world", kT0 + 110 * kMs, kT0 + 110 * kMs));
  t.accept();
  // Beyond max_future_stamp: a refusal, which does not move the order check.
  EXPECT_FALSE(t.checkHeader("world", kT0 + 10 * kSecond, kT0 + 120 * kMs));
  EXPECT_EQ(t.guard().lastKind(), Rejection::kFuture);
  EXPECT_TRUE(t.checkHeader("world", kT0 + 130 * kMs, kT0 + 130 * kMs));
}

TEST(InputTimeline, AfterAJumpBackOlderStatesAreNewAgain) {
  InputTimeline t = stateTimeline();
  ASSERT_TRUE(t.checkHeader("world", kT0, kT0));
  t.accept();
  EXPECT_TRUE(t.checkHeader("world", kT0 - 10 * kSecond, kT0 - 10 * kSecond));
  EXPECT_EQ(t.superseded(), 0u);
}

}  // namespace
}  // namespace projection_collision_avoidance
