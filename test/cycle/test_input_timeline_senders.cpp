// InputTimeline: the rules that keep one message or one sender from taking an input (one
// publisher at a time, implausible stamps, a timeline locked out for its timeout, an estimate
// that cannot be led). No master.
#include <cstdint>
#include <string>

#include <gtest/gtest.h>

#include "projection_collision_avoidance/cycle/InputTimeline.hpp"

namespace projection_collision_avoidance {
namespace {

constexpr std::int64_t kSecond = 1000000000;
constexpr std::int64_t kMs = 1000000;
constexpr std::int64_t kT0 = 1000 * kSecond;

/// A measurement's timeline: frame "world", 0.1 s ahead at most, 0.5 s old at most (its timeout).
InputTimelineOptions optionsOf(ClockPolicy policy = ClockPolicy::kStamps) {
  InputTimelineOptions o;
  o.limits = {"world", 0.1, 0.5};
  o.correction.policy = policy;
  return o;
}

/// Sends a message of @p publisher stamped @p stamp at @p now; true when it was accepted.
bool send(InputTimeline& t, std::int64_t stamp, std::int64_t now, const std::string& publisher) {
  if (!t.checkHeader("world", stamp, now, publisher)) {
    return false;
  }
  t.accept();
  return true;
}

TEST(InputTimelineSenders, TheFirstPublisherHoldsTheInputUntilItGoesQuiet) {
  InputTimeline t("relative_measurement", optionsOf());
  EXPECT_DOUBLE_EQ(t.timeout(), 0.5);  // max_age
  ASSERT_TRUE(send(t, kT0, kT0, "/plant"));
  EXPECT_EQ(t.holder(), "/plant");
  // A second publisher whose stamps run ahead of the first: refused, counted, and its stamps
  // move nothing (the holder's next message is still in order).
  EXPECT_FALSE(send(t, kT0 + 50 * kMs, kT0 + 5 * kMs, "/intruder"));
  EXPECT_EQ(t.guard().lastKind(), Rejection::kPublisher);
  EXPECT_NE(t.guard().lastRejection().find("/intruder"), std::string::npos);
  EXPECT_EQ(t.foreignMessages(), 1u);
  EXPECT_EQ(t.foreignHeard(), kT0 + 5 * kMs);
  EXPECT_TRUE(send(t, kT0 + 10 * kMs, kT0 + 10 * kMs, "/plant"));
  // The holder's refused messages still keep it: a message stamped 0 is heard.
  EXPECT_FALSE(send(t, 0, kT0 + 400 * kMs, "/plant"));
  EXPECT_FALSE(send(t, kT0 + 800 * kMs, kT0 + 800 * kMs, "/intruder"));
  EXPECT_EQ(t.guard().lastKind(), Rejection::kPublisher);
  // Quiet for more than the timeout: the next publisher heard takes the input, afresh (its
  // stamps may lie before the old holder's).
  EXPECT_TRUE(send(t, kT0 + 850 * kMs, kT0 + 901 * kMs, "/intruder"));
  EXPECT_EQ(t.holder(), "/intruder");
  EXPECT_EQ(t.handovers(), 1u);
  EXPECT_FALSE(send(t, kT0 + 910 * kMs, kT0 + 910 * kMs, "/plant"));
  EXPECT_EQ(t.foreignMessages(), 3u);
  // Without a name (a message made within the node) the rule does not apply.
  EXPECT_TRUE(send(t, kT0 + 920 * kMs, kT0 + 920 * kMs, ""));
}

TEST(InputTimelineSenders, TimeGoingBackKeepsTheHolder) {
  InputTimeline t("relative_measurement", optionsOf());
  ASSERT_TRUE(send(t, kT0, kT0, "/plant"));
  // The clock restarts 100 s earlier: the holder keeps the input from then on.
  EXPECT_FALSE(send(t, kT0 - 100 * kSecond, kT0 - 100 * kSecond, "/intruder"));
  EXPECT_EQ(t.guard().lastKind(), Rejection::kPublisher);
  EXPECT_TRUE(send(t, kT0 - 100 * kSecond + kMs, kT0 - 100 * kSecond + kMs, "/plant"));
}

TEST(InputTimelineSenders, ACommandWithoutHeaderFollowsTheSameRule) {
  InputTimelineOptions o;
  o.timeout = 0.25;
  InputTimeline t("cmd_vel", o);
  EXPECT_TRUE(t.checkReceipt(kT0, "/adapter"));
  t.accept();
  EXPECT_FALSE(t.checkReceipt(kT0 + kMs, "/teleop"));
  EXPECT_EQ(t.guard().lastKind(), Rejection::kPublisher);
  EXPECT_EQ(t.rejected(), 1u);
  EXPECT_TRUE(t.checkReceipt(kT0 + 300 * kMs, "/teleop"));
}

TEST(InputTimelineSenders, StampsFarFromTheClockAreImplausibleUnderReceiptAndEstimate) {
  for (const ClockPolicy policy : {ClockPolicy::kReceipt, ClockPolicy::kEstimate}) {
    InputTimeline t("relative_measurement", optionsOf(policy));  // max_offset 60 s
    ASSERT_TRUE(send(t, kT0 - 2 * kSecond, kT0, "/sensor"));     // 2 s behind: plausible
    for (const std::int64_t off : {61 * kSecond, -61 * kSecond, kT0 - 1}) {
      EXPECT_FALSE(send(t, kT0 + off, kT0 + 10 * kMs, "/sensor")) << toString(policy);
      EXPECT_EQ(t.guard().lastKind(), Rejection::kImplausible);
    }
    // Nothing moved: the next message of the sensor is in order and corrected as before.
    EXPECT_TRUE(send(t, kT0 - 2 * kSecond + 20 * kMs, kT0 + 20 * kMs, "/sensor"));
    EXPECT_NEAR(t.age(kT0 + 20 * kMs), 0.0, 1e-3) << toString(policy);
  }
  // Under "stamps" a stamp far ahead is refused as such (future), as before.
  InputTimeline t("relative_measurement", optionsOf(ClockPolicy::kStamps));
  EXPECT_FALSE(send(t, kT0 + 61 * kSecond, kT0, "/sensor"));
  EXPECT_EQ(t.guard().lastKind(), Rejection::kFuture);
}

TEST(InputTimelineSenders, AStampAcceptedFarAheadLocksTheOrderForTheTimeoutOnly) {
  // Under "receipt" a stamp 30 s ahead (within max_offset) of the holder itself is accepted and
  // its raw stamp would refuse every later one as out of order.
  InputTimeline t("relative_measurement", optionsOf(ClockPolicy::kReceipt));
  ASSERT_TRUE(send(t, kT0, kT0, "/sensor"));
  ASSERT_TRUE(send(t, kT0 + 30 * kSecond, kT0 + 10 * kMs, "/sensor"));
  std::int64_t now = kT0 + 20 * kMs;
  int refused = 0;
  for (; now < kT0 + 2 * kSecond && !send(t, now, now, "/sensor"); now += 10 * kMs) {
    EXPECT_EQ(t.guard().lastKind(), Rejection::kOutOfOrder);
    ++refused;
  }
  // The first message more than the timeout (0.5 s) after the last acceptance starts afresh.
  EXPECT_GT(now, kT0 + 510 * kMs);
  EXPECT_LE(now, kT0 + 520 * kMs);
  EXPECT_EQ(refused, 50);
  EXPECT_EQ(t.restarts(), 1u);
  EXPECT_NEAR(t.age(now), 0.0, 1e-12);
  EXPECT_TRUE(send(t, now + 10 * kMs, now + 10 * kMs, "/sensor"));
}

TEST(InputTimelineSenders, AClockStepOfTheSenderIsTakenAfreshAfterTheTimeout) {
  // Under "estimate" a sender whose clock steps 3 s ahead is refused as ahead of the clock
  // (the offset moves 1 ms a second), then taken afresh with its new skew.
  InputTimeline t("relative_measurement", optionsOf(ClockPolicy::kEstimate));
  std::int64_t now = kT0;
  for (; now < kT0 + kSecond; now += 10 * kMs) {
    ASSERT_TRUE(send(t, now - 5 * kMs, now, "/sensor"));
  }
  const std::int64_t stepped = now;
  while (!send(t, now + 3 * kSecond - 5 * kMs, now, "/sensor") && now < stepped + 2 * kSecond) {
    EXPECT_EQ(t.guard().lastKind(), Rejection::kFuture);
    now += 10 * kMs;
  }
  EXPECT_GE(now - stepped, 490 * kMs);  // the last acceptance was 10 ms before the step
  EXPECT_LE(now - stepped, 510 * kMs);
  EXPECT_EQ(t.restarts(), 1u);
  EXPECT_NEAR(t.skew(), -2.995, 1e-9);
}

TEST(InputTimelineSenders, ASenderCannotDragTheEstimateAndADelayThatGrowsIsAge) {
  // The holder leads its stamps 1 ms further per message: between two fresh starts the offset
  // moves 1 ms a second, so the stamps more than max_future_stamp (0.1 s) ahead of the clock
  // are refused; each fresh start comes after the timeout (0.5 s) without an acceptance. (Not
  // the holder, such a sender is refused outright.)
  InputTimeline t("relative_measurement", optionsOf(ClockPolicy::kEstimate));
  std::int64_t now = kT0;
  int accepted = 0;
  for (int k = 0; now < kT0 + 4 * kSecond; now += 10 * kMs, ++k) {
    const std::int64_t stamp = now - 5 * kMs + k * kMs;
    if (send(t, stamp, now, "/sensor")) {
      ++accepted;
      EXPECT_LE(t.stamp(), now + 100 * kMs);
    }
  }
  EXPECT_LT(accepted, 400);
  EXPECT_GE(t.restarts(), 2u);
  // Honest again: taken within the timeout, at an age that errs on the old side (the offset the
  // sender led, within max_age) or afresh.
  const std::int64_t stopped = now;
  while (!send(t, now - 5 * kMs, now, "/sensor") && now < stopped + 2 * kSecond) {
    now += 10 * kMs;
  }
  EXPECT_LE(now - stopped, 510 * kMs);
  EXPECT_GE(t.age(now), 0.0);
  EXPECT_LE(t.age(now), 0.5);
  // A delay that grows 0.1 s a second for 3 s: the age reported grows with it (the window's
  // smallest delay, 5 ms, apart).
  InputTimeline g("relative_measurement", optionsOf(ClockPolicy::kEstimate));
  now = kT0;
  int k = 0;
  for (; now <= kT0 + 3 * kSecond; now += 10 * kMs, ++k) {
    ASSERT_TRUE(send(g, now - 5 * kMs - k * kMs, now, "/sensor"));
  }
  EXPECT_NEAR(g.age(now - 10 * kMs), 0.1 * 3.0, 0.003);
}

}  // namespace
}  // namespace projection_collision_avoidance
