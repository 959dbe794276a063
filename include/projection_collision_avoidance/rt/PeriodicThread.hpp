#pragma once

/// @file
/// A periodic real-time thread for the follower's control loop (~control_loop: thread), and
/// locking the process's memory (~lock_memory). Plain POSIX (clock_nanosleep, pthread, mlockall):
/// no ROS, so that it can be tested without a master.

#include <atomic>
#include <chrono>
#include <cstdint>
#include <functional>
#include <future>
#include <string>
#include <system_error>
#include <thread>

namespace projection_collision_avoidance {

/// Now on CLOCK_MONOTONIC, in nanoseconds.
std::int64_t monotonicNanoseconds();

/// One call of a PeriodicThread's callback. Times are CLOCK_MONOTONIC nanoseconds.
struct PeriodicTick {
  std::uint64_t index = 0;    ///< k: the deadline this call is for (1, 2, ... from the start)
  std::int64_t expected = 0;  ///< the deadline, start + k * period
  std::int64_t actual = 0;    ///< when the thread woke for it (>= expected)
  std::uint64_t skipped = 0;  ///< deadlines skipped just before this one (previous call overran)
  std::int64_t period = 0;    ///< the thread's period
};

/// The kernel refused a PeriodicThread its SCHED_FIFO priority; code() is the errno (EPERM without
/// CAP_SYS_NICE or a high enough RLIMIT_RTPRIO).
class PriorityRefused : public std::system_error {
 public:
  PriorityRefused(int error, const std::string& what)
      : std::system_error(error, std::generic_category(), what) {}
};

/// A thread that calls a function at absolute deadlines start + k * period (k = 1, 2, ...),
/// sleeping with clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME) between them, optionally under
/// SCHED_FIFO. The schedule never drifts: when a call returns after the next deadline (it overran,
/// or the thread woke late), the deadlines already past are skipped, counted in the next call's
/// PeriodicTick::skipped and in missedPeriods(), and the thread re-aligns to the next future one.
///
/// stop() (or the destructor) ends the thread within min(one period, 10 ms) plus the running
/// call: the sleep is cut into slices of at most 10 ms between which a stop flag is checked.
class PeriodicThread {
 public:
  /// Called once per deadline, on the periodic thread. Must not throw (std::terminate).
  using Callback = std::function<void(const PeriodicTick&)>;

  PeriodicThread() = default;
  /// Stops and joins the thread if it runs.
  ~PeriodicThread();
  PeriodicThread(const PeriodicThread&) = delete;
  PeriodicThread& operator=(const PeriodicThread&) = delete;
  PeriodicThread(PeriodicThread&&) = delete;
  PeriodicThread& operator=(PeriodicThread&&) = delete;

  /// Starts the thread: deadlines every @p period from now, or, with a @p phase, at the times
  /// phase + k * period of CLOCK_MONOTONIC, so that threads of one period started with
  /// different phases keep that offset between their deadlines (their work does not collide).
  /// @param period    > 0
  /// @param priority  0: the thread keeps the scheduling policy and priority of the caller;
  ///                  1 to 99: SCHED_FIFO at that priority (pthread_setschedparam), set by the
  ///                  thread before its first deadline
  /// @param callback  what to run at each deadline
  /// @param name      the thread's name as ps and /proc/<pid>/task/<tid>/comm show it (at most
  ///                  15 characters are kept); empty: the caller's
  /// @param phase     in [0, period): deadlines on that grid; kFromNow (default): from now
  /// @throws std::invalid_argument for a period <= 0, a priority outside [0, 99], a phase
  ///         outside [0, period) or no callback
  /// @throws std::logic_error when the thread already runs
  /// @throws PriorityRefused when the priority is refused; the thread has then ended
  /// @throws std::system_error when no thread can be created
  void start(std::chrono::nanoseconds period, int priority, Callback callback,
             const std::string& name = std::string(), std::chrono::nanoseconds phase = kFromNow);

  /// start()'s phase for deadlines every period from the start.
  static constexpr std::chrono::nanoseconds kFromNow{-1};

  /// Asks the thread to end and joins it; returns once it has ended. Does nothing when it does
  /// not run. Not to be called from the callback.
  void stop();

  /// Whether the thread runs (started and not stopped).
  bool running() const { return thread_.joinable(); }

  /// Deadlines skipped since start() (the sum of PeriodicTick::skipped).
  std::uint64_t missedPeriods() const { return missed_.load(std::memory_order_relaxed); }

  /// Longest slice of sleep between two looks at the stop flag.
  static constexpr std::chrono::nanoseconds kStopCheckInterval = std::chrono::milliseconds(10);

 private:
  /// The thread's body: sets the priority, reports the outcome to start() through @p started
  /// (0 or the errno), then loops until stop().
  void run(std::int64_t period, std::int64_t phase, int priority, const Callback& callback,
           const std::string& name, std::promise<int> started);
  /// Sleeps until @p deadline (monotonic ns) in slices; false when asked to stop meanwhile.
  bool sleepUntil(std::int64_t deadline) const;

  std::thread thread_;
  std::atomic<bool> stop_{false};
  std::atomic<std::uint64_t> missed_{0};
};

/// Locks the process's current and future pages in RAM: mlockall(MCL_CURRENT | MCL_FUTURE), so
/// that a page fault cannot stall the control loop. For a nodelet this is the whole manager.
/// @throws std::system_error (code: the errno: EPERM or ENOMEM without CAP_IPC_LOCK and with a
///         small RLIMIT_MEMLOCK)
void lockProcessMemory();

}  // namespace projection_collision_avoidance
