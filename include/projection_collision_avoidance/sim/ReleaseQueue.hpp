#pragma once

/// @file
/// Messages held until their release time, bounded in count and in bytes: the simulated link's
/// queue (LinkRelay). ROS-free, header-only (any payload).

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <utility>
#include <vector>

namespace projection_collision_avoidance {

/// A min-heap of payloads on their release time (s), ties in the order they were pushed, holding
/// at most max_items payloads and max_bytes bytes (as the caller sizes them). Full, it drops the
/// oldest pushed until the new one fits. Its storage is reserved at construction: push() and
/// pop() allocate nothing. Not thread-safe.
template <typename Payload>
class ReleaseQueue {
 public:
  /// What push() did.
  struct PushResult {
    bool accepted = false;    ///< false: larger than max_bytes alone (nothing dropped)
    std::size_t dropped = 0;  ///< held payloads dropped (oldest first) to make room
  };

  /// @throws std::invalid_argument if @p max_items or @p max_bytes is 0
  ReleaseQueue(std::size_t max_items, std::size_t max_bytes)
      : max_items_(max_items), max_bytes_(max_bytes) {
    if (max_items == 0 || max_bytes == 0) {
      throw std::invalid_argument("ReleaseQueue: max_items and max_bytes must be > 0");
    }
    heap_.reserve(max_items);
  }

  /// Holds @p payload of @p bytes bytes until @p release (s).
  PushResult push(double release, std::size_t bytes, Payload payload) {
    PushResult result;
    if (bytes > max_bytes_) {
      return result;
    }
    while (!heap_.empty() && (heap_.size() >= max_items_ || bytes_ + bytes > max_bytes_)) {
      dropOldest();
      ++result.dropped;
    }
    heap_.push_back(Entry{release, next_sequence_++, bytes, std::move(payload)});
    std::push_heap(heap_.begin(), heap_.end(), Later());
    bytes_ += bytes;
    result.accepted = true;
    return result;
  }

  bool empty() const { return heap_.empty(); }
  std::size_t size() const { return heap_.size(); }
  /// Bytes held (the sum of the sizes pushed and not yet popped or dropped).
  std::size_t bytes() const { return bytes_; }
  /// The earliest release time held (s); only when not empty().
  double nextRelease() const { return heap_.front().release; }

  /// Removes and returns the payload of the earliest release (the first pushed among equal ones);
  /// only when not empty().
  Payload pop() {
    std::pop_heap(heap_.begin(), heap_.end(), Later());
    Entry entry = std::move(heap_.back());
    heap_.pop_back();
    bytes_ -= entry.bytes;
    return std::move(entry.payload);
  }

  void clear() {
    heap_.clear();
    bytes_ = 0;
  }

 private:
  struct Entry {
    double release;
    std::uint64_t sequence;
    std::size_t bytes;
    Payload payload;
  };
  /// The heap's order: the top is the earliest release, then the first pushed.
  struct Later {
    bool operator()(const Entry& a, const Entry& b) const {
      return a.release > b.release || (a.release == b.release && a.sequence > b.sequence);
    }
  };

  /// Drops the first pushed of those held (a linear search: only when full).
  void dropOldest() {
    const auto oldest =
        std::min_element(heap_.begin(), heap_.end(),
                         [](const Entry& a, const Entry& b) { return a.sequence < b.sequence; });
    bytes_ -= oldest->bytes;
    if (oldest != heap_.end() - 1) {
      *oldest = std::move(heap_.back());
    }
    heap_.pop_back();
    std::make_heap(heap_.begin(), heap_.end(), Later());
  }

  std::size_t max_items_;
  std::size_t max_bytes_;
  std::vector<Entry> heap_;
  std::size_t bytes_ = 0;
  std::uint64_t next_sequence_ = 0;
};

}  // namespace projection_collision_avoidance
