#pragma once

#include <cstddef>
#include <cstdint>

#include "projection_collision_avoidance/rt/Doorbell.hpp"
#include "projection_collision_avoidance/rt/SpscQueue.hpp"

namespace projection_collision_avoidance {

/// Hands items from a real-time thread to a worker thread: post() copies the item into a
/// preallocated lock-free ring and rings a doorbell (no allocation, no lock, no waiting; a full
/// ring drops the item and counts it); the worker takes them with pop() and sleeps in wait().
template <typename T, std::size_t Capacity>
class Handoff {
 public:
  /// The real-time side.
  void post(const T& item) {
    queue_.push(item);
    doorbell_.ring();
  }
  /// The worker's side: the oldest item into @p item; false when there is none.
  bool pop(T* item) { return queue_.pop(item); }
  /// The worker's side: the doorbell's count, to pass to wait() after draining.
  std::uint32_t count() const { return doorbell_.count(); }
  /// The worker's side: sleeps until a post() after @p seen, or @p timeout_ns.
  std::uint32_t wait(std::uint32_t seen, std::int64_t timeout_ns) {
    return doorbell_.wait(seen, timeout_ns);
  }
  /// Wakes the worker without an item (to make it look at a stop flag).
  void wake() { doorbell_.ring(); }
  /// Items dropped because the ring was full.
  std::uint64_t dropped() const { return queue_.dropped(); }

 private:
  SpscQueue<T, Capacity> queue_;
  Doorbell doorbell_;
};

}  // namespace projection_collision_avoidance
