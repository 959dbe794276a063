#include "projection_collision_avoidance/rt/PeriodicThread.hpp"

#include <algorithm>
#include <cerrno>
#include <ctime>
#include <stdexcept>
#include <string>
#include <system_error>
#include <utility>

#include <pthread.h>
#include <sched.h>
#include <sys/mman.h>

namespace projection_collision_avoidance {
namespace {

constexpr std::int64_t kNanosecondsPerSecond = 1000000000;
constexpr int kMaxPriority = 99;            ///< SCHED_FIFO's highest on Linux
constexpr std::size_t kMaxNameLength = 15;  ///< a thread's name, without its terminating 0

timespec toTimespec(std::int64_t nanoseconds) {
  timespec time{};
  time.tv_sec = static_cast<time_t>(nanoseconds / kNanosecondsPerSecond);
  time.tv_nsec = static_cast<long>(nanoseconds % kNanosecondsPerSecond);
  return time;
}

}  // namespace

std::int64_t monotonicNanoseconds() {
  timespec now{};
  clock_gettime(CLOCK_MONOTONIC, &now);
  return static_cast<std::int64_t>(now.tv_sec) * kNanosecondsPerSecond + now.tv_nsec;
}

PeriodicThread::~PeriodicThread() { stop(); }

void PeriodicThread::start(std::chrono::nanoseconds period, int priority, Callback callback,
                           const std::string& name, std::chrono::nanoseconds phase) {
  if (period.count() <= 0) {
    throw std::invalid_argument("PeriodicThread: the period must be positive, got " +
                                std::to_string(period.count()) + " ns");
  }
  if (priority < 0 || priority > kMaxPriority) {
    throw std::invalid_argument("PeriodicThread: the priority must lie in [0, " +
                                std::to_string(kMaxPriority) + "], got " +
                                std::to_string(priority));
  }
  if (phase != kFromNow && (phase.count() < 0 || phase >= period)) {
    throw std::invalid_argument(
        "PeriodicThread: the phase must lie in [0, period = " + std::to_string(period.count()) +
        " ns), got " + std::to_string(phase.count()) + " ns");
  }
  if (!callback) {
    throw std::invalid_argument("PeriodicThread: no callback");
  }
  if (running()) {
    throw std::logic_error("PeriodicThread: already running");
  }
  stop_.store(false, std::memory_order_release);
  missed_.store(0, std::memory_order_relaxed);
  std::promise<int> started;
  std::future<int> outcome = started.get_future();
  thread_ = std::thread(&PeriodicThread::run, this, static_cast<std::int64_t>(period.count()),
                        static_cast<std::int64_t>(phase.count()), priority, std::move(callback),
                        name.substr(0, kMaxNameLength), std::move(started));
  const int error = outcome.get();
  if (error != 0) {
    thread_.join();  // it has returned already
    throw PriorityRefused(
        error, "pthread_setschedparam(SCHED_FIFO, priority " + std::to_string(priority) + ")");
  }
}

void PeriodicThread::stop() {
  if (!thread_.joinable()) {
    return;
  }
  stop_.store(true, std::memory_order_release);
  thread_.join();
}

void PeriodicThread::run(std::int64_t period, std::int64_t phase, int priority,
                         const Callback& callback, const std::string& name,
                         std::promise<int> started) {
  if (!name.empty()) {
    pthread_setname_np(pthread_self(), name.c_str());  // only fails for a name too long
  }
  if (priority > 0) {
    sched_param parameters{};
    parameters.sched_priority = priority;
    const int error = pthread_setschedparam(pthread_self(), SCHED_FIFO, &parameters);
    if (error != 0) {
      started.set_value(error);
      return;
    }
  }
  std::int64_t start = monotonicNanoseconds();
  if (phase >= 0) {  // the last time phase + j * period not after now
    start -= ((start - phase) % period + period) % period;
  }
  started.set_value(0);
  PeriodicTick tick;
  tick.period = period;
  std::int64_t k = 1;
  std::int64_t skipped = 0;
  while (sleepUntil(start + k * period)) {
    tick.index = static_cast<std::uint64_t>(k);
    tick.expected = start + k * period;
    tick.actual = monotonicNanoseconds();
    tick.skipped = static_cast<std::uint64_t>(skipped);
    callback(tick);
    // Re-align to the first deadline still ahead; the ones already past are skipped.
    ++k;
    const std::int64_t now = monotonicNanoseconds();
    const std::int64_t next = start + k * period;
    skipped = next <= now ? (now - next) / period + 1 : 0;
    k += skipped;
    missed_.fetch_add(static_cast<std::uint64_t>(skipped), std::memory_order_relaxed);
  }
}

bool PeriodicThread::sleepUntil(std::int64_t deadline) const {
  for (;;) {
    if (stop_.load(std::memory_order_acquire)) {
      return false;
    }
    const std::int64_t wake =
        std::min(deadline, monotonicNanoseconds() + kStopCheckInterval.count());
    const timespec until = toTimespec(wake);
    while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &until, nullptr) == EINTR) {
    }
    if (wake == deadline) {
      return !stop_.load(std::memory_order_acquire);
    }
  }
}

void lockProcessMemory() {
  if (mlockall(MCL_CURRENT | MCL_FUTURE) != 0) {
    throw std::system_error(errno, std::generic_category(), "mlockall(MCL_CURRENT | MCL_FUTURE)");
  }
}

}  // namespace projection_collision_avoidance
