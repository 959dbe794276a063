#pragma once

#include <atomic>
#include <cstdint>

namespace projection_collision_avoidance {

/// The latest value of something one thread writes and another reads, without locks: a triple
/// buffer. write() never waits for the reader and read() never waits for the writer; neither
/// allocates (T lives in the object, three copies). The reader always gets the newest value
/// completely written before its read() began, or keeps the one it had.
///
/// One writer thread and one reader thread (each may change over time if they hand over
/// properly, e.g. through a join). T must be copy-assignable; copying it must not allocate for
/// the whole to be allocation-free (fixed-size Eigen types, plain structs).
template <typename T>
class LatestValue {
 public:
  /// Publishes @p value (the writer's side): copies it into the back buffer and swaps that with
  /// the middle one.
  void write(const T& value) {
    buffers_[back_] = value;
    const std::uint8_t previous =
        middle_.exchange(static_cast<std::uint8_t>(back_ | kFresh), std::memory_order_acq_rel);
    back_ = previous & kIndex;
  }

  /// Takes the newest value written since the last read() into the reader's buffer (the
  /// reader's side). Returns false, leaving it unchanged, when nothing new was written.
  bool read() {
    if ((middle_.load(std::memory_order_relaxed) & kFresh) == 0) {
      return false;
    }
    const std::uint8_t previous = middle_.exchange(front_, std::memory_order_acq_rel);
    front_ = previous & kIndex;
    return true;
  }

  /// The reader's current value (default-constructed until the first successful read()).
  const T& value() const { return buffers_[front_]; }

 private:
  static constexpr std::uint8_t kIndex = 0x3;
  static constexpr std::uint8_t kFresh = 0x4;

  T buffers_[3] = {};
  std::uint8_t back_ = 0;                ///< the writer's buffer
  std::atomic<std::uint8_t> middle_{1};  ///< index of the middle buffer, | kFresh when new
  std::uint8_t front_ = 2;               ///< the reader's buffer
};

}  // namespace projection_collision_avoidance
