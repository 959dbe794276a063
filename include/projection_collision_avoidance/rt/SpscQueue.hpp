#pragma once

#include <array>
#include <atomic>
#include <cstddef>
#include <cstdint>

namespace projection_collision_avoidance {

/// A bounded queue from one producer thread to one consumer thread, without locks: a ring of
/// Capacity preallocated slots. push() never waits and never allocates; when the ring is full it
/// refuses the new item and counts it (dropped()), so a slow consumer can never hold the producer
/// back. The consumer takes items in order with pop().
///
/// For a real-time producer: T's copy assignment must not allocate (fixed-size Eigen types,
/// plain structs).
template <typename T, std::size_t Capacity>
class SpscQueue {
  static_assert(Capacity >= 2 && (Capacity & (Capacity - 1)) == 0,
                "Capacity must be a power of two");

 public:
  /// Appends a copy of @p item (the producer's side); false, with the item dropped and counted,
  /// when the ring is full.
  bool push(const T& item) {
    const std::uint64_t head = head_.load(std::memory_order_relaxed);
    if (head - tail_.load(std::memory_order_acquire) >= Capacity) {
      dropped_.fetch_add(1, std::memory_order_relaxed);
      return false;
    }
    slots_[head & (Capacity - 1)] = item;
    head_.store(head + 1, std::memory_order_release);
    return true;
  }

  /// Moves the oldest item into @p item (the consumer's side); false when the queue is empty.
  bool pop(T* item) {
    const std::uint64_t tail = tail_.load(std::memory_order_relaxed);
    if (tail == head_.load(std::memory_order_acquire)) {
      return false;
    }
    *item = slots_[tail & (Capacity - 1)];
    tail_.store(tail + 1, std::memory_order_release);
    return true;
  }

  /// Items pushed since construction, dropped ones not included.
  std::uint64_t pushed() const { return head_.load(std::memory_order_acquire); }
  /// Items refused because the ring was full.
  std::uint64_t dropped() const { return dropped_.load(std::memory_order_relaxed); }

 private:
  std::array<T, Capacity> slots_{};
  alignas(64) std::atomic<std::uint64_t> head_{0};  ///< next slot to write (producer)
  alignas(64) std::atomic<std::uint64_t> tail_{0};  ///< next slot to read (consumer)
  std::atomic<std::uint64_t> dropped_{0};
};

}  // namespace projection_collision_avoidance
