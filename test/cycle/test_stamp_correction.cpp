// StampCorrection: the skew of a sender's stamps and the offset each policy adds to them.
#include <cmath>
#include <cstdint>
#include <limits>
#include <stdexcept>

#include <gtest/gtest.h>

#include "projection_collision_avoidance/cycle/StampCorrection.hpp"

namespace projection_collision_avoidance {
namespace {

constexpr std::int64_t kSecond = 1000000000;
constexpr std::int64_t kMs = 1000000;

StampCorrection correctionOf(ClockPolicy policy, double window = 10.0, double max_offset = 60.0) {
  StampCorrectionOptions o;
  o.policy = policy;
  o.window = window;
  o.max_offset = max_offset;
  return StampCorrection(o);
}

TEST(StampCorrection, StampsAreTakenAsTheyAreByDefault) {
  StampCorrection c = correctionOf(ClockPolicy::kStamps);
  c.accepted(100 * kSecond, 102 * kSecond);
  EXPECT_EQ(c.offsetFor(101 * kSecond, 103 * kSecond), 0);
  EXPECT_DOUBLE_EQ(c.lastSkew(), 2.0);  // still measured
}

TEST(StampCorrection, ReceiptGivesEachMessageItsOwnSkew) {
  StampCorrection c = correctionOf(ClockPolicy::kReceipt);
  EXPECT_EQ(c.offsetFor(100 * kSecond, 98 * kSecond), -2 * kSecond);  // a sender 2 s ahead
  EXPECT_EQ(c.offsetFor(100 * kSecond, 100 * kSecond + 5 * kMs), 5 * kMs);
  EXPECT_EQ(c.offsetFor(0, 100 * kSecond), 0);  // a zero stamp stays refusable
}

TEST(StampCorrection, EstimateTakesTheSmallestSkewOfTheWindow) {
  // A sender 2 s behind, delays of 3 to 12 ms: the estimate is 2 s + 3 ms, and a message
  // delayed 12 ms is corrected to 9 ms old.
  StampCorrection c = correctionOf(ClockPolicy::kEstimate);
  const std::int64_t offset = 2 * kSecond;
  std::int64_t receipt = 1000 * kSecond;
  EXPECT_EQ(c.offsetFor(receipt - offset - 7 * kMs, receipt), offset + 7 * kMs);  // none yet
  for (int k = 0; k < 500; ++k) {
    receipt += 10 * kMs;
    const std::int64_t delay = (3 + (k * 7) % 10) * kMs;
    const std::int64_t stamp = receipt - offset - delay;
    c.accepted(stamp, receipt);
  }
  receipt += 10 * kMs;
  const std::int64_t stamp = receipt - offset - 12 * kMs;
  const std::int64_t corrected = stamp + c.offsetFor(stamp, receipt);
  EXPECT_EQ(receipt - corrected, 9 * kMs);
  EXPECT_NEAR(c.minimumSkew(receipt), 2.003, 1e-12);
}

TEST(StampCorrection, EstimateForgetsWhatLeftTheWindow) {
  StampCorrection c = correctionOf(ClockPolicy::kEstimate, 1.6);  // buckets of 0.1 s
  c.accepted(0 * kSecond + 1, 1 * kSecond);                       // skew ~1 s
  EXPECT_NEAR(c.minimumSkew(1 * kSecond), 1.0, 1e-6);
  c.accepted(2 * kSecond - 5 * kSecond, 2 * kSecond);   // skew 5 s, within max_offset
  EXPECT_NEAR(c.minimumSkew(2 * kSecond), 1.0, 1e-6);   // 1 s ago: still in the window
  EXPECT_NEAR(c.minimumSkew(2700 * kMs), 5.0, 1e-6);    // 1.7 s later: the first has left it
  EXPECT_TRUE(std::isnan(c.minimumSkew(4 * kSecond)));  // both have
}

TEST(StampCorrection, AClockStepOfTheSenderForwardIsFollowedAtOnce) {
  StampCorrection c = correctionOf(ClockPolicy::kEstimate);
  std::int64_t receipt = 50 * kSecond;
  for (int k = 0; k < 100; ++k, receipt += 10 * kMs) {
    c.accepted(receipt - 1 * kMs, receipt);
  }
  // The sender's clock jumps 3 s ahead: its skew becomes −3 s, smaller, so the minimum at once.
  c.accepted(receipt + 3 * kSecond - 1 * kMs, receipt);
  const std::int64_t stamp = receipt + 10 * kMs + 3 * kSecond - 1 * kMs;
  EXPECT_EQ(stamp + c.offsetFor(stamp, receipt + 10 * kMs), receipt + 10 * kMs);
}

TEST(StampCorrection, SkewsBeyondMaxOffsetAreMeasuredButNotLearnt) {
  StampCorrection c = correctionOf(ClockPolicy::kEstimate, 10.0, 5.0);
  c.accepted(100 * kSecond - 2 * kMs, 100 * kSecond);
  c.accepted(100 * kSecond + 3600 * kSecond, 100 * kSecond + 10 * kMs);  // an hour ahead
  EXPECT_DOUBLE_EQ(c.lastSkew(), -3600.0 + 0.01);
  EXPECT_NEAR(c.minimumSkew(100 * kSecond + 10 * kMs), 0.002, 1e-12);
  // Stamps at the ends of ros::Time's range do not overflow.
  const std::int64_t latest = std::int64_t{4294967295} * kSecond + 999999999;
  c.accepted(latest, 100 * kSecond);
  EXPECT_LT(c.lastSkew(), -4e9);
  EXPECT_NEAR(c.minimumSkew(100 * kSecond + 10 * kMs), 0.002, 1e-12);
}

TEST(StampCorrection, ResetForgetsEverything) {
  StampCorrection c = correctionOf(ClockPolicy::kEstimate);
  c.accepted(10 * kSecond, 11 * kSecond);
  c.reset();
  EXPECT_TRUE(std::isnan(c.lastSkew()));
  EXPECT_TRUE(std::isnan(c.minimumSkew(11 * kSecond)));
  EXPECT_EQ(c.offsetFor(10 * kSecond, 10 * kSecond + 4 * kMs), 4 * kMs);  // its own again
}

TEST(StampCorrection, OptionsOutOfRangeAreRefusedByName) {
  const auto refused = [](double window, double max_offset, const char* key) {
    try {
      correctionOf(ClockPolicy::kEstimate, window, max_offset);
      ADD_FAILURE() << key << " accepted";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(key), std::string::npos) << e.what();
    }
  };
  refused(0.0, 1.0, "window");
  refused(std::numeric_limits<double>::quiet_NaN(), 1.0, "window");
  refused(1.0, -1.0, "max_offset");
  refused(1.0, std::numeric_limits<double>::infinity(), "max_offset");
}

}  // namespace
}  // namespace projection_collision_avoidance
