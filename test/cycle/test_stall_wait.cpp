/// StallWait, the follower cycle's wait for input after a stall (no master): when a wait begins,
/// what ends it, and what does not start one.

#include <cstdint>

#include <gtest/gtest.h>

#include "projection_collision_avoidance/cycle/StallWait.hpp"

namespace projection_collision_avoidance {
namespace {

constexpr std::int64_t kMs = 1000000;  // ns
constexpr double kTimeout = 0.5;       // s: a wait begins past 0.25 s of stall
constexpr double kPeriod = 0.001;      // s

TEST(StallWait, TicksOnTimeNeverWait) {
  StallWait wait(kTimeout, kPeriod);
  for (int k = 0; k < 1000; ++k) {
    EXPECT_FALSE(wait.holds(k * kMs, 0.0, 7));
    EXPECT_EQ(wait.stall(), 0.0);
  }
}

TEST(StallWait, ALateTickWaitsUntilANewMeasurement) {
  StallWait wait(kTimeout, kPeriod);
  EXPECT_FALSE(wait.holds(0, 0.0, 1));
  EXPECT_TRUE(wait.holds(kMs, 0.3, 1));  // 0.3 s late on ROS time
  EXPECT_DOUBLE_EQ(wait.stall(), 0.3);
  EXPECT_TRUE(wait.holds(2 * kMs, 0.0, 1));
  EXPECT_EQ(wait.stall(), 0.0);               // reported at the tick that saw it
  EXPECT_FALSE(wait.holds(3 * kMs, 0.0, 2));  // a measurement accepted meanwhile ends it
  EXPECT_FALSE(wait.holds(4 * kMs, 0.0, 2));
}

TEST(StallWait, AWaitWithoutInputEndsAfterHalfTheTimeout) {
  StallWait wait(kTimeout, kPeriod);
  EXPECT_FALSE(wait.holds(0, 0.0, 1));
  EXPECT_TRUE(wait.holds(kMs, 0.3, 1));
  std::int64_t t = kMs;
  while (wait.holds(t, 0.0, 1)) {
    t += kMs;
    ASSERT_LT(t, 10000 * kMs);
  }
  EXPECT_NEAR(1e-9 * static_cast<double>(t - kMs), 0.5 * kTimeout, 0.002);
}

TEST(StallWait, AStallOnTheSteadyClockAloneWaitsOnlyWhileMeasurementsAreFuture) {
  StallWait quiet(kTimeout, kPeriod);
  EXPECT_FALSE(quiet.holds(0, 0.0, 1));
  EXPECT_FALSE(quiet.holds(400 * kMs, 0.0, 1));  // a lockstep simulation that stood still
  EXPECT_NEAR(quiet.stall(), 0.399, 1e-9);

  StallWait replayed(kTimeout, kPeriod);
  EXPECT_FALSE(replayed.holds(0, 0.0, 1));
  replayed.noteFutureMeasurement();  // a replaying clock refuses the newest as future
  EXPECT_TRUE(replayed.holds(400 * kMs, 0.0, 1));
  EXPECT_TRUE(replayed.holds(401 * kMs, 0.0, 1));
  EXPECT_FALSE(replayed.holds(402 * kMs, 0.0, 2));
}

TEST(StallWait, FutureRefusalsExtendTheWaitAtMostToItsLimit) {
  StallWait wait(kTimeout, kPeriod);
  EXPECT_FALSE(wait.holds(0, 0.0, 1));
  EXPECT_TRUE(wait.holds(kMs, 0.3, 1));  // limit max(0.5, 0.3) = 0.5 s
  std::int64_t t = kMs;
  do {
    wait.noteFutureMeasurement();  // every tick: the clock keeps catching up
    t += kMs;
    ASSERT_LT(t, 10000 * kMs);
  } while (wait.holds(t, 0.0, 1));
  EXPECT_NEAR(1e-9 * static_cast<double>(t - kMs), kTimeout, 0.002);
}

}  // namespace
}  // namespace projection_collision_avoidance
