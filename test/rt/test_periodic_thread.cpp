/// The follower's periodic real-time thread (PeriodicThread, lockProcessMemory): a plain gtest,
/// no master. Timing is never asserted tightly: each test runs until enough calls were observed
/// or a generous wall-clock deadline passed, and bounds counts by the elapsed time it measured.
/// What must hold exactly does: deadlines at start + k * period, every deadline either run or
/// counted as skipped, and wake-ups never before their deadline.

#include <cerrno>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <fstream>
#include <mutex>
#include <stdexcept>
#include <string>
#include <system_error>
#include <thread>
#include <vector>

#include <gtest/gtest.h>
#include <pthread.h>
#include <sched.h>
#include <sys/mman.h>

#include "projection_collision_avoidance/rt/PeriodicThread.hpp"

namespace projection_collision_avoidance {
namespace {

using std::chrono::milliseconds;
using std::chrono::nanoseconds;

constexpr double kDeadlineSeconds = 5.0;  ///< wall time to wait for the calls a test needs

/// What the tests keep of the calls: the ticks, and the policy and priority they ran under.
class Recorder {
 public:
  /// Records one call; sleeps @p overrun_ms in every @p overrun_every-th call (0: never).
  explicit Recorder(int overrun_every = 0, int overrun_ms = 0)
      : overrun_every_(overrun_every), overrun_ms_(overrun_ms) {}

  PeriodicThread::Callback callback() {
    return [this](const PeriodicTick& tick) { record(tick); };
  }

  /// Waits until @p count calls were recorded or kDeadlineSeconds passed; whether they were.
  bool waitFor(std::size_t count) {
    std::unique_lock<std::mutex> lock(mutex_);
    return changed_.wait_for(lock, std::chrono::duration<double>(kDeadlineSeconds),
                             [this, count] { return ticks_.size() >= count; });
  }

  std::vector<PeriodicTick> ticks() {
    const std::lock_guard<std::mutex> lock(mutex_);
    return ticks_;
  }

  int policy() {
    const std::lock_guard<std::mutex> lock(mutex_);
    return policy_;
  }

  int priority() {
    const std::lock_guard<std::mutex> lock(mutex_);
    return priority_;
  }

 private:
  void record(const PeriodicTick& tick) {
    int policy = -1;
    sched_param parameters{};
    pthread_getschedparam(pthread_self(), &policy, &parameters);
    std::size_t count = 0;
    {
      const std::lock_guard<std::mutex> lock(mutex_);
      ticks_.push_back(tick);
      policy_ = policy;
      priority_ = parameters.sched_priority;
      count = ticks_.size();
    }
    changed_.notify_all();
    if (overrun_every_ > 0 && count % static_cast<std::size_t>(overrun_every_) == 0) {
      std::this_thread::sleep_for(milliseconds(overrun_ms_));
    }
  }

  const int overrun_every_;
  const int overrun_ms_;
  std::mutex mutex_;
  std::condition_variable changed_;
  std::vector<PeriodicTick> ticks_;
  int policy_ = -1;
  int priority_ = -1;
};

/// The exact invariants of a run's calls: index k, expected = first deadline + (k - 1) * period,
/// every deadline either run or skipped (index gap = 1 + skipped), never woken before the
/// deadline.
void expectSchedule(const std::vector<PeriodicTick>& ticks, std::int64_t period) {
  ASSERT_FALSE(ticks.empty());
  const std::int64_t first =
      ticks.front().expected - static_cast<std::int64_t>(ticks.front().index - 1) * period;
  std::uint64_t previous = 0;
  for (const PeriodicTick& tick : ticks) {
    EXPECT_EQ(tick.period, period);
    EXPECT_EQ(tick.index, previous + 1 + tick.skipped)
        << "a deadline neither run nor counted as skipped before call " << tick.index;
    EXPECT_EQ(tick.expected - first, static_cast<std::int64_t>(tick.index - 1) * period)
        << "deadline " << tick.index << " is not on the grid of the period";
    EXPECT_GE(tick.actual, tick.expected) << "woke before deadline " << tick.index;
    previous = tick.index;
  }
}

TEST(PeriodicThread, CallsAtAbsoluteDeadlinesOfThePeriod) {
  const std::int64_t period = 10 * 1000 * 1000;  // 10 ms
  const std::size_t wanted = 50;
  Recorder recorder;
  PeriodicThread thread;
  const std::int64_t started = monotonicNanoseconds();
  thread.start(nanoseconds(period), 0, recorder.callback());
  EXPECT_TRUE(thread.running());
  ASSERT_TRUE(recorder.waitFor(wanted))
      << "fewer than " << wanted << " calls in " << kDeadlineSeconds << " s at a 10 ms period";
  thread.stop();
  const std::int64_t observed = monotonicNanoseconds();  // after every call
  EXPECT_FALSE(thread.running());
  const std::vector<PeriodicTick> ticks = recorder.ticks();
  expectSchedule(ticks, period);
  // The first deadline is one period after start(); none is later than now.
  EXPECT_GE(ticks.front().expected, started + period);
  EXPECT_LE(ticks.back().expected, observed);
  // No more calls than deadlines in the time measured (and no bursts to catch up).
  const std::int64_t deadlines_passed = (observed - started) / period;
  EXPECT_LE(static_cast<std::int64_t>(ticks.size()), deadlines_passed);
  // Every deadline up to the last call is a call or a skipped one.
  std::uint64_t skipped = 0;
  for (const PeriodicTick& tick : ticks) {
    skipped += tick.skipped;
  }
  EXPECT_EQ(ticks.back().index, ticks.size() + skipped);
  EXPECT_GE(thread.missedPeriods(), skipped);  // it may have skipped more after the last call
  // The calls stop with stop().
  const std::size_t after_stop = recorder.ticks().size();
  std::this_thread::sleep_for(milliseconds(30));
  EXPECT_EQ(recorder.ticks().size(), after_stop);
}

TEST(PeriodicThread, APhasePutsTheDeadlinesOnItsGrid) {
  const std::int64_t period = 10 * 1000 * 1000;
  const std::int64_t phase = 3 * 1000 * 1000;
  Recorder recorder;
  PeriodicThread thread;
  const std::int64_t started = monotonicNanoseconds();
  thread.start(nanoseconds(period), 0, recorder.callback(), "phased", nanoseconds(phase));
  const std::int64_t returned = monotonicNanoseconds();  // the thread read its clock before
  ASSERT_TRUE(recorder.waitFor(10));
  thread.stop();
  const std::vector<PeriodicTick> ticks = recorder.ticks();
  expectSchedule(ticks, period);
  for (const PeriodicTick& tick : ticks) {
    EXPECT_EQ(tick.expected % period, phase) << "deadline " << tick.index << " off the grid";
  }
  // The first deadline is the first point of the grid after the thread read its clock, which it
  // did within start(): after `started`, and at most a period after `returned`.
  EXPECT_GT(ticks.front().expected - static_cast<std::int64_t>(ticks.front().index - 1) * period,
            started);
  EXPECT_LE(ticks.front().expected - static_cast<std::int64_t>(ticks.front().index - 1) * period,
            returned + period);
}

TEST(PeriodicThread, OverrunsSkipTheDeadlinesAlreadyPast) {
  // Every 5th call takes 2.5 periods: the two deadlines that pass meanwhile are skipped (more if
  // the machine delays the thread further), and the next call says so.
  const std::int64_t period = 10 * 1000 * 1000;
  const int overrun_every = 5;
  Recorder recorder(overrun_every, 25);
  PeriodicThread thread;
  thread.start(nanoseconds(period), 0, recorder.callback());
  const std::size_t wanted = 21;  // four overruns and the calls after them
  ASSERT_TRUE(recorder.waitFor(wanted));
  thread.stop();
  const std::vector<PeriodicTick> ticks = recorder.ticks();
  expectSchedule(ticks, period);
  std::uint64_t skipped = 0;
  for (std::size_t i = 0; i < ticks.size(); ++i) {
    skipped += ticks[i].skipped;
    if (i > 0 && i % overrun_every == 0) {  // the call after an overrunning one
      EXPECT_GE(ticks[i].skipped, 2U) << "call " << i + 1 << " follows a 2.5-period overrun";
      EXPECT_GE(ticks[i].index - ticks[i - 1].index, 3U);
    }
  }
  EXPECT_GE(skipped, 2U * ((ticks.size() - 1) / overrun_every));
  EXPECT_GE(thread.missedPeriods(), skipped);
}

TEST(PeriodicThread, StopReturnsWithoutWaitingForTheNextDeadline) {
  // A 2 s period: stop() must not wait for the deadline, only for the next 10 ms slice.
  Recorder recorder;
  PeriodicThread thread;
  thread.start(std::chrono::seconds(2), 0, recorder.callback());
  std::this_thread::sleep_for(milliseconds(50));  // well inside the first period
  const auto before = std::chrono::steady_clock::now();
  thread.stop();
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - before).count();
  EXPECT_LT(seconds, 0.5) << "stop() waited for the period";
  EXPECT_FALSE(thread.running());
  EXPECT_TRUE(recorder.ticks().empty());
  thread.stop();  // again: nothing to do
}

TEST(PeriodicThread, DestructorStopsARunningThread) {
  Recorder recorder;
  {
    PeriodicThread thread;
    thread.start(milliseconds(5), 0, recorder.callback());
    ASSERT_TRUE(recorder.waitFor(3));
  }  // would std::terminate on a joinable std::thread
  const std::size_t calls = recorder.ticks().size();
  std::this_thread::sleep_for(milliseconds(20));
  EXPECT_EQ(recorder.ticks().size(), calls);
}

TEST(PeriodicThread, PriorityZeroLeavesTheSchedulerAlone) {
  int policy = -1;
  sched_param parameters{};
  ASSERT_EQ(pthread_getschedparam(pthread_self(), &policy, &parameters), 0);
  Recorder recorder;
  PeriodicThread thread;
  thread.start(milliseconds(5), 0, recorder.callback());
  ASSERT_TRUE(recorder.waitFor(2));
  thread.stop();
  EXPECT_EQ(recorder.policy(), policy);
  EXPECT_EQ(recorder.priority(), parameters.sched_priority);
}

TEST(PeriodicThread, PriorityRunsTheThreadUnderSchedFifo) {
  const int priority = 10;
  Recorder recorder;
  PeriodicThread thread;
  try {
    thread.start(milliseconds(5), priority, recorder.callback());
  } catch (const PriorityRefused& error) {
    EXPECT_FALSE(thread.running()) << "a refused priority must leave no thread behind";
    if (error.code() == std::errc::operation_not_permitted) {
      GTEST_SKIP() << "SCHED_FIFO refused here (EPERM: no CAP_SYS_NICE and RLIMIT_RTPRIO below "
                   << priority << "): " << error.what();
    }
    FAIL() << "the priority was refused otherwise than with EPERM: " << error.what();
  }
  ASSERT_TRUE(recorder.waitFor(3));
  thread.stop();
  EXPECT_EQ(recorder.policy(), SCHED_FIFO);
  EXPECT_EQ(recorder.priority(), priority);
  expectSchedule(recorder.ticks(), 5 * 1000 * 1000);
  // The caller's own scheduling is untouched.
  int policy = -1;
  sched_param parameters{};
  ASSERT_EQ(pthread_getschedparam(pthread_self(), &policy, &parameters), 0);
  EXPECT_NE(policy, SCHED_FIFO);
}

TEST(PeriodicThread, RefusesBadArguments) {
  Recorder recorder;
  PeriodicThread thread;
  EXPECT_THROW(thread.start(nanoseconds(0), 0, recorder.callback()), std::invalid_argument);
  EXPECT_THROW(thread.start(nanoseconds(-1), 0, recorder.callback()), std::invalid_argument);
  EXPECT_THROW(thread.start(milliseconds(1), -1, recorder.callback()), std::invalid_argument);
  EXPECT_THROW(thread.start(milliseconds(1), 100, recorder.callback()), std::invalid_argument);
  EXPECT_THROW(thread.start(milliseconds(1), 0, PeriodicThread::Callback()), std::invalid_argument);
  EXPECT_THROW(thread.start(milliseconds(1), 0, recorder.callback(), "", milliseconds(1)),
               std::invalid_argument);
  EXPECT_THROW(thread.start(milliseconds(1), 0, recorder.callback(), "", nanoseconds(-2)),
               std::invalid_argument);
  EXPECT_FALSE(thread.running());
  thread.start(milliseconds(5), 0, recorder.callback());
  EXPECT_THROW(thread.start(milliseconds(5), 0, recorder.callback()), std::logic_error);
  thread.stop();
  // It can start again once stopped, on a fresh schedule.
  const std::size_t before = recorder.ticks().size();
  thread.start(milliseconds(5), 0, recorder.callback());
  ASSERT_TRUE(recorder.waitFor(before + 2));
  thread.stop();
  const std::vector<PeriodicTick> ticks = recorder.ticks();
  EXPECT_EQ(ticks[before].index, 1U + ticks[before].skipped);
}

/// VmLck of this process, in kB (-1 when /proc does not say).
long lockedKilobytes() {
  std::ifstream status("/proc/self/status");
  for (std::string line; std::getline(status, line);) {
    if (line.rfind("VmLck:", 0) == 0) {
      return std::stol(line.substr(6));
    }
  }
  return -1;
}

TEST(LockProcessMemory, LocksThePagesOrSaysWhyNot) {
  try {
    lockProcessMemory();
  } catch (const std::system_error& error) {
    EXPECT_NE(std::string(error.what()).find("mlockall"), std::string::npos) << error.what();
    if (error.code() == std::errc::operation_not_permitted ||
        error.code() == std::errc::not_enough_memory) {
      GTEST_SKIP() << "mlockall refused here (no CAP_IPC_LOCK, small RLIMIT_MEMLOCK): "
                   << error.what();
    }
    FAIL() << "mlockall failed otherwise than EPERM or ENOMEM: " << error.what();
  }
  const long locked = lockedKilobytes();
  munlockall();
  EXPECT_GT(locked, 0) << "VmLck after mlockall";
}

}  // namespace
}  // namespace projection_collision_avoidance
