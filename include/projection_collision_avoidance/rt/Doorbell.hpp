#pragma once

#include <atomic>
#include <cerrno>
#include <cstdint>

#include <linux/futex.h>
#include <sys/syscall.h>
#include <time.h>
#include <unistd.h>

namespace projection_collision_avoidance {

/// Wakes one waiting thread from a thread that must not block (Linux futex): ring() bumps a
/// counter and asks the kernel to wake a waiter; it takes no lock and allocates nothing. wait()
/// sleeps until the counter differs from the value the caller last saw, so a ring between the
/// caller's look and its sleep is never lost (the kernel compares before it sleeps).
class Doorbell {
 public:
  /// Bumps the counter and wakes the waiter, if any (the ringing side; never blocks).
  void ring() {
    count_.fetch_add(1, std::memory_order_release);
    syscall(SYS_futex, reinterpret_cast<std::uint32_t*>(&count_), FUTEX_WAKE_PRIVATE, 1, nullptr,
            nullptr, 0);
  }

  /// The counter now (the waiting side reads it, handles what is ready, then waits on it).
  std::uint32_t count() const { return count_.load(std::memory_order_acquire); }

  /// Sleeps until the counter differs from @p seen or @p timeout_ns passes (then also on a
  /// signal). Returns the counter.
  std::uint32_t wait(std::uint32_t seen, std::int64_t timeout_ns) {
    if (count() == seen) {
      timespec timeout{static_cast<time_t>(timeout_ns / 1000000000),
                       static_cast<long>(timeout_ns % 1000000000)};
      syscall(SYS_futex, reinterpret_cast<std::uint32_t*>(&count_), FUTEX_WAIT_PRIVATE, seen,
              &timeout, nullptr, 0);
    }
    return count();
  }

 private:
  static_assert(sizeof(std::atomic<std::uint32_t>) == sizeof(std::uint32_t),
                "the futex word is the atomic's storage");
  std::atomic<std::uint32_t> count_{0};
};

}  // namespace projection_collision_avoidance
