#pragma once

#include <atomic>
#include <cstdint>

#include <ros/callback_queue_interface.h>

namespace projection_collision_avoidance {

/// A callback queue that queues nothing: addCallback() runs the callback at once, on the thread
/// that adds it. For a subscription that is roscpp's network thread (or, between nodelets, the
/// publisher's thread), so a message reaches its callback without a hand-off to a spinner thread
/// (a futex wake-up and a context switch per message, the largest part of a small node's CPU
/// time at 1 kHz).
///
/// Only for callbacks that are short and never block: they run inside roscpp's I/O loop, which
/// handles no other socket meanwhile. Not for timers: roscpp's timer thread adds a timer's callback
/// with its own locks held, which the callback takes again (it would deadlock).
///
/// A callback that answers TryAgain (a subscription whose previous call still runs on another
/// thread) is tried again until it answers otherwise; Invalid ones (a subscription shut down) are
/// dropped.
class InlineCallbackQueue : public ros::CallbackQueueInterface {
 public:
  void addCallback(const ros::CallbackInterfacePtr& callback, uint64_t owner_id) override;
  /// Nothing is queued, so there is nothing to remove.
  void removeByID(uint64_t owner_id) override;

  /// Callbacks run (Success), tries that answered TryAgain, callbacks dropped as Invalid or not
  /// ready.
  std::uint64_t called() const { return called_.load(std::memory_order_relaxed); }
  std::uint64_t retried() const { return retried_.load(std::memory_order_relaxed); }
  std::uint64_t dropped() const { return dropped_.load(std::memory_order_relaxed); }

 private:
  std::atomic<std::uint64_t> called_{0};
  std::atomic<std::uint64_t> retried_{0};
  std::atomic<std::uint64_t> dropped_{0};
};

}  // namespace projection_collision_avoidance
