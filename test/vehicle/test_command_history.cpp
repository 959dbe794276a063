/// CommandHistory: the command in force at a time, the sum of the increments of a half-open
/// interval, the ring dropping its oldest, the newest replaced by what was sent, time going back,
/// and inputs it ignores.

#include <cmath>
#include <limits>
#include <string>

#include <gtest/gtest.h>

#include "projection_collision_avoidance/core/ParameterError.hpp"
#include "projection_collision_avoidance/vehicle/CommandHistory.hpp"

namespace projection_collision_avoidance {
namespace {

AxisVector vec(double x) { return AxisVector::Constant(1, x); }

TEST(CommandHistory, RefusesNoCapacityAndBadAxes) {
  EXPECT_THROW(CommandHistory(0, 2), ParameterError);
  EXPECT_THROW(CommandHistory(4, 0), ParameterError);
  EXPECT_THROW(CommandHistory(4, 4), ParameterError);
  EXPECT_NO_THROW(CommandHistory(1, 3));
}

TEST(CommandHistory, TheCommandInForceIsTheLastSentBeforeTheTime) {
  CommandHistory history(8, 1);
  AxisVector v = vec(-7.0);
  EXPECT_FALSE(history.commandBefore(1.0, &v));
  history.push(1.0, vec(10.0), vec(1.0));
  history.push(2.0, vec(20.0), vec(2.0));
  EXPECT_FALSE(history.commandBefore(1.0, &v));  // sent at 1.0: not before it
  EXPECT_EQ(v(0), -7.0);
  ASSERT_TRUE(history.commandBefore(std::nextafter(1.0, 2.0), &v));
  EXPECT_EQ(v(0), 10.0);
  ASSERT_TRUE(history.commandBefore(2.0, &v));
  EXPECT_EQ(v(0), 10.0);
  ASSERT_TRUE(history.commandBefore(5.0, &v));
  EXPECT_EQ(v(0), 20.0);
}

TEST(CommandHistory, IncrementsAreSummedOverAHalfOpenInterval) {
  CommandHistory history(8, 1);
  for (int k = 1; k <= 5; ++k) {
    history.push(k, vec(k), vec(k));  // increments 1 … 5 at t = 1 … 5
  }
  EXPECT_EQ(history.incrementBetween(2.0, 4.0)(0), 2.0 + 3.0);
  EXPECT_EQ(history.incrementBetween(1.5, 5.0)(0), 2.0 + 3.0 + 4.0);
  EXPECT_EQ(history.incrementBetween(5.0, 9.0)(0), 5.0);
  EXPECT_EQ(history.incrementBetween(5.5, 9.0)(0), 0.0);
  EXPECT_EQ(history.incrementBetween(-std::numeric_limits<double>::infinity(),
                                     std::numeric_limits<double>::infinity())(0),
            15.0);
}

TEST(CommandHistory, AFullRingDropsItsOldest) {
  CommandHistory history(3, 1);
  for (int k = 1; k <= 5; ++k) {
    history.push(k, vec(10.0 * k), vec(k));
  }
  EXPECT_EQ(history.size(), 3U);
  EXPECT_EQ(history.fromNewest(0).time, 5.0);
  EXPECT_EQ(history.fromNewest(2).time, 3.0);
  AxisVector v = vec(0.0);
  EXPECT_FALSE(history.commandBefore(3.0, &v));
  EXPECT_EQ(history.incrementBetween(0.0, 10.0)(0), 3.0 + 4.0 + 5.0);
}

TEST(CommandHistory, ReplacingTheNewestMovesItsIncrementByAsMuch) {
  CommandHistory history(4, 1);
  history.replaceNewest(vec(1.0));  // empty: nothing to replace
  EXPECT_EQ(history.size(), 0U);
  history.push(1.0, vec(2.0), vec(0.5));
  history.replaceNewest(vec(1.75));
  EXPECT_EQ(history.fromNewest(0).velocity(0), 1.75);
  EXPECT_EQ(history.fromNewest(0).increment(0), 0.25);
}

TEST(CommandHistory, TimeGoingBackStartsTheHistoryAfresh) {
  CommandHistory history(4, 1);
  history.push(10.0, vec(1.0), vec(1.0));
  history.push(10.0, vec(2.0), vec(1.0));  // the same time is not going back
  EXPECT_EQ(history.size(), 2U);
  history.push(3.0, vec(5.0), vec(5.0));
  EXPECT_EQ(history.size(), 1U);
  EXPECT_EQ(history.fromNewest(0).time, 3.0);
}

TEST(CommandHistory, IgnoresValuesThatAreNotFiniteOrOfOtherAxes) {
  constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
  CommandHistory history(4, 2);
  AxisVector two = AxisVector::Zero(2);
  history.push(kNaN, two, two);
  history.push(1.0, vec(1.0), two);
  two(1) = kNaN;
  history.push(1.0, two, AxisVector::Zero(2));
  EXPECT_EQ(history.size(), 0U);
  history.push(1.0, AxisVector::Zero(2), AxisVector::Zero(2));
  history.replaceNewest(two);
  EXPECT_TRUE(history.fromNewest(0).velocity.allFinite());
}

}  // namespace
}  // namespace projection_collision_avoidance
