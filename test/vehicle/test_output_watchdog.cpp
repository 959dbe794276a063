/// OutputWatchdog: the stop before any command, a command fresh at exactly the timeout and
/// stale one step past it, the stop's first tick flagged once, time going back, unusable times.

#include <cmath>
#include <limits>
#include <string>

#include <gtest/gtest.h>

#include "projection_collision_avoidance/core/ParameterError.hpp"
#include "projection_collision_avoidance/vehicle/OutputWatchdog.hpp"

namespace projection_collision_avoidance {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

std::string refusedKey(double timeout) {
  try {
    OutputWatchdog watchdog(timeout);
  } catch (const ParameterError& e) {
    return e.key();
  }
  return "";
}

TEST(OutputWatchdog, RefusesUnusableTimeouts) {
  for (double timeout : {0.0, -1.0, kInf, kNaN}) {
    EXPECT_EQ(refusedKey(timeout), "vehicle.command_timeout") << timeout;
  }
  EXPECT_EQ(refusedKey(0.5), "");
}

TEST(OutputWatchdog, StopsUntilTheFirstCommand) {
  OutputWatchdog watchdog(0.5);
  WatchdogDecision d = watchdog.check(3.0);
  EXPECT_TRUE(d.send_stop);
  EXPECT_TRUE(d.stop_began);
  EXPECT_EQ(d.state, WatchdogState::kNoCommandYet);
  d = watchdog.check(3.1);
  EXPECT_TRUE(d.send_stop);  // repeated at every check
  EXPECT_FALSE(d.stop_began);
  ASSERT_TRUE(watchdog.commandSent(3.2));
  d = watchdog.check(3.2);
  EXPECT_FALSE(d.send_stop);
  EXPECT_FALSE(d.stop_began);
  EXPECT_EQ(d.state, WatchdogState::kFresh);
}

TEST(OutputWatchdog, FreshAtTheTimeoutStoppedOnePast) {
  OutputWatchdog watchdog(0.5);
  ASSERT_TRUE(watchdog.commandSent(10.0));
  EXPECT_FALSE(watchdog.check(10.0).send_stop);
  EXPECT_FALSE(watchdog.check(10.5).send_stop);
  WatchdogDecision d = watchdog.check(std::nextafter(10.5, kInf));
  EXPECT_TRUE(d.send_stop);
  EXPECT_TRUE(d.stop_began);
  EXPECT_EQ(d.state, WatchdogState::kTimedOut);
  EXPECT_STREQ(toString(d.state), "timed_out");
  d = watchdog.check(11.0);
  EXPECT_TRUE(d.send_stop);
  EXPECT_FALSE(d.stop_began);
  // A new command resumes; the next timeout begins a new stop.
  ASSERT_TRUE(watchdog.commandSent(11.0));
  EXPECT_EQ(watchdog.check(11.25).state, WatchdogState::kFresh);
  d = watchdog.check(12.0);
  EXPECT_TRUE(d.send_stop);
  EXPECT_TRUE(d.stop_began);
}

TEST(OutputWatchdog, TimeGoingBackStopsUntilANewCommand) {
  OutputWatchdog watchdog(0.5);
  ASSERT_TRUE(watchdog.commandSent(20.0));
  EXPECT_FALSE(watchdog.check(20.1).send_stop);
  WatchdogDecision d = watchdog.check(std::nextafter(20.0, -kInf));
  EXPECT_TRUE(d.send_stop);
  EXPECT_TRUE(d.stop_began);
  EXPECT_EQ(d.state, WatchdogState::kTimeWentBack);
  // The command of the old time line is forgotten: still stopped when time passes it again.
  d = watchdog.check(20.1);
  EXPECT_TRUE(d.send_stop);
  EXPECT_EQ(d.state, WatchdogState::kNoCommandYet);
  ASSERT_TRUE(watchdog.commandSent(1.0));  // a looping bag started over
  EXPECT_EQ(watchdog.check(1.25).state, WatchdogState::kFresh);
}

TEST(OutputWatchdog, UnusableTimes) {
  OutputWatchdog watchdog(0.5);
  ASSERT_TRUE(watchdog.commandSent(5.0));
  EXPECT_FALSE(watchdog.commandSent(kNaN));
  EXPECT_FALSE(watchdog.commandSent(kInf));
  EXPECT_FALSE(watchdog.check(5.25).send_stop);  // the command of 5.0 s still counts
  const WatchdogDecision d = watchdog.check(kNaN);
  EXPECT_TRUE(d.send_stop);
  EXPECT_EQ(d.state, WatchdogState::kInvalidTime);
  EXPECT_FALSE(watchdog.check(5.5).send_stop);
  watchdog.reset();
  EXPECT_EQ(watchdog.check(5.5).state, WatchdogState::kNoCommandYet);
  EXPECT_STREQ(toString(WatchdogState::kTimeWentBack), "time_went_back");
}

}  // namespace
}  // namespace projection_collision_avoidance
