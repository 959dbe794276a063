// SharedTicker: members of one period share one thread, called in turn at each deadline; leaving
// stops a member's calls; other periods get threads of their own. No ROS.
#include <atomic>
#include <chrono>
#include <functional>
#include <memory>
#include <mutex>
#include <stdexcept>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "projection_collision_avoidance/rt/SharedTicker.hpp"

namespace projection_collision_avoidance {
namespace {

constexpr std::chrono::milliseconds kPeriod{5};
constexpr std::chrono::seconds kDeadline{10};  ///< for each awaited condition

/// Waits until @p condition holds or kDeadline passes; whether it held.
bool waitFor(const std::function<bool()>& condition) {
  const auto end = std::chrono::steady_clock::now() + kDeadline;
  while (!condition()) {
    if (std::chrono::steady_clock::now() > end) {
      return false;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  return true;
}

/// What one member saw: each call's deadline index, thread and start time.
struct Calls {
  std::mutex mutex;
  std::vector<std::uint64_t> index;
  std::vector<std::int64_t> actual;
  std::vector<std::thread::id> thread;
  std::atomic<std::size_t> count{0};
  SharedTicker::Callback callback() {
    return [this](const PeriodicTick& tick) {
      const std::lock_guard<std::mutex> lock(mutex);
      index.push_back(tick.index);
      actual.push_back(tick.actual);
      thread.push_back(std::this_thread::get_id());
      ++count;
    };
  }
};

TEST(SharedTicker, MembersOfOnePeriodShareOneThreadAndEveryDeadline) {
  Calls a;
  Calls b;
  auto first = std::make_unique<SharedTicker>(kPeriod, "test ticks", a.callback());
  auto second = std::make_unique<SharedTicker>(kPeriod, "ignored", b.callback());
  EXPECT_EQ(first->groupSize(), 2U);
  ASSERT_TRUE(waitFor([&] { return b.count >= 20; }));
  second.reset();
  first.reset();
  const std::lock_guard<std::mutex> lock_a(a.mutex);
  const std::lock_guard<std::mutex> lock_b(b.mutex);
  for (const std::thread::id& id : b.thread) {
    EXPECT_EQ(id, a.thread.front());
  }
  EXPECT_NE(a.thread.front(), std::this_thread::get_id());
  // Every deadline b was called at, a was called at too, and first (it joined first).
  for (std::size_t i = 0; i < b.index.size(); ++i) {
    bool found = false;
    for (std::size_t j = 0; j < a.index.size(); ++j) {
      if (a.index[j] == b.index[i]) {
        found = true;
        EXPECT_LE(a.actual[j], b.actual[i]) << "deadline " << b.index[i];
      }
    }
    EXPECT_TRUE(found) << "deadline " << b.index[i] << " called for b only";
  }
}

TEST(SharedTicker, OtherPeriodsGetThreadsOfTheirOwn) {
  Calls a;
  Calls b;
  const SharedTicker first(kPeriod, "test ticks", a.callback());
  const SharedTicker second(2 * kPeriod, "test ticks 2", b.callback());
  EXPECT_EQ(first.groupSize(), 1U);
  EXPECT_EQ(second.groupSize(), 1U);
  ASSERT_TRUE(waitFor([&] { return a.count >= 5 && b.count >= 5; }));
  const std::lock_guard<std::mutex> lock_a(a.mutex);
  const std::lock_guard<std::mutex> lock_b(b.mutex);
  EXPECT_NE(a.thread.front(), b.thread.front());
}

TEST(SharedTicker, LeavingStopsTheMembersCallsAndTheOthersGoOn) {
  Calls a;
  Calls b;
  const SharedTicker first(kPeriod, "test ticks", a.callback());
  auto second = std::make_unique<SharedTicker>(kPeriod, "test ticks", b.callback());
  ASSERT_TRUE(waitFor([&] { return b.count >= 3; }));
  second.reset();  // waits for a running round
  const std::size_t b_after = b.count;
  const std::size_t a_after = a.count;
  ASSERT_TRUE(waitFor([&] { return a.count >= a_after + 10; }));
  EXPECT_EQ(b.count, b_after);
  EXPECT_EQ(first.groupSize(), 1U);
}

TEST(SharedTicker, ALastMemberLeavingEndsTheGroup) {
  Calls a;
  Calls b;
  auto first = std::make_unique<SharedTicker>(kPeriod, "test ticks", a.callback());
  ASSERT_TRUE(waitFor([&] { return a.count >= 2; }));
  first.reset();
  const SharedTicker again(kPeriod, "test ticks", b.callback());
  EXPECT_EQ(again.groupSize(), 1U);
  ASSERT_TRUE(waitFor([&] { return b.count >= 2; }));  // a new group's thread calls it
}

TEST(SharedTicker, RefusesANonPositivePeriodOrNoCallback) {
  EXPECT_THROW(SharedTicker(std::chrono::nanoseconds(0), "x", [](const PeriodicTick&) {}),
               std::invalid_argument);
  EXPECT_THROW(SharedTicker(kPeriod, "x", SharedTicker::Callback()), std::invalid_argument);
}

}  // namespace
}  // namespace projection_collision_avoidance
