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

StampCorrection correctionOf(ClockPolicy policy, double window = 10.0, double max_offset = 60.0,
                             double max_drift_rate = 1e-3) {
  StampCorrectionOptions o;
  o.policy = policy;
  o.window = window;
  o.max_offset = max_offset;
  o.max_drift_rate = max_drift_rate;
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

TEST(StampCorrection, AClockStepOfTheSenderMovesTheOffsetOnlyAtTheDriftRate) {
  StampCorrection c = correctionOf(ClockPolicy::kEstimate);  // 1 ms a second
  std::int64_t receipt = 50 * kSecond;
  for (int k = 0; k < 100; ++k, receipt += 10 * kMs) {
    const std::int64_t stamp = receipt - 1 * kMs;
    c.accepted(stamp, receipt, c.offsetFor(stamp, receipt));
  }
  // The sender's clock jumps 3 s ahead: its skew becomes −3 s, the window's minimum at once,
  // but the offset moves by 1 ms a second from 1 ms (InputTimeline refuses the stamps as
  // ahead of the clock until it starts afresh).
  c.accepted(receipt + 3 * kSecond - 1 * kMs, receipt, kMs);
  EXPECT_NEAR(c.minimumSkew(receipt), -3.0 + 0.001, 1e-12);
  const std::int64_t stamp = receipt + 2 * kSecond + 3 * kSecond - 1 * kMs;
  EXPECT_EQ(c.offsetFor(stamp, receipt + 2 * kSecond), kMs - 2 * kMs);
  // Without an offset used before (the first message, or after reset()) it is the minimum.
  c.reset();
  EXPECT_EQ(c.offsetFor(stamp, receipt + 2 * kSecond), receipt - stamp + 2 * kSecond);
}

/// The offset after @p messages 10 ms apart, each stamped @p lead ns further from a 2 ms delay
/// than the one before.
std::int64_t offsetAfterALead(std::int64_t lead, int messages) {
  StampCorrection c = correctionOf(ClockPolicy::kEstimate);  // 1 ms a second
  std::int64_t receipt = 100 * kSecond;
  std::int64_t offset = 0;
  for (int k = 0; k < messages; ++k, receipt += 10 * kMs) {
    const std::int64_t stamp = receipt - 2 * kMs + k * lead;
    offset = c.offsetFor(stamp, receipt);
    c.accepted(stamp, receipt, offset);
  }
  return offset;
}

TEST(StampCorrection, ASenderLeadingItsStampsCannotLeadTheEstimate) {
  // Every message 1 ms further ahead: by 4 s its stamps are 0.4 s ahead; the offset moved 4 ms.
  EXPECT_NEAR(static_cast<double>(offsetAfterALead(kMs, 400) - 2 * kMs) / kSecond, -0.004, 3e-5);
  // A delay growing by 0.1 s/s for 20 s (2 s in all): the window's minimum grows by 1 s once the
  // first 10 s have left it, the offset by at most 20 ms; the rest stays visible as age.
  const double moved = static_cast<double>(offsetAfterALead(-kMs, 2000) - 2 * kMs) / kSecond;
  EXPECT_GT(moved, 0.0);
  EXPECT_LE(moved, 0.020 + 1e-9);
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
  const auto refused = [](double window, double max_offset, const char* key,
                          double max_drift_rate = 1e-3) {
    try {
      correctionOf(ClockPolicy::kEstimate, window, max_offset, max_drift_rate);
      ADD_FAILURE() << key << " accepted";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(key), std::string::npos) << e.what();
    }
  };
  refused(0.0, 1.0, "window");
  refused(std::numeric_limits<double>::quiet_NaN(), 1.0, "window");
  refused(1.0, -1.0, "max_offset");
  refused(1.0, std::numeric_limits<double>::infinity(), "max_offset");
  refused(1.0, 1.0, "max_drift_rate", -1e-3);
  refused(1.0, 1.0, "max_drift_rate", 1.5);
  refused(1.0, 1.0, "max_drift_rate", std::numeric_limits<double>::quiet_NaN());
}

}  // namespace
}  // namespace projection_collision_avoidance
