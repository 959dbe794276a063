#pragma once

/// @file
/// Senders' stamps put on the receiver's clock when the two clocks disagree (hosts without
/// chrony/NTP; doc/multi_host.md): the skew each message shows, and the offset a policy adds to
/// its stamp before it is judged.

#include <array>
#include <cstdint>
#include <limits>

namespace projection_collision_avoidance {

/// How a sender's stamps are read (~clock_skew/policy).
enum class ClockPolicy : std::uint8_t {
  kStamps,    ///< "stamps": as they are (synchronised clocks; the default)
  kReceipt,   ///< "receipt": each message as stamped at its receipt (age 0 on arrival)
  kEstimate,  ///< "estimate": stamp + the smallest receipt − stamp of a sliding window
};

/// "stamps", "receipt", "estimate".
const char* toString(ClockPolicy policy);

/// Options of StampCorrection.
struct StampCorrectionOptions {
  ClockPolicy policy = ClockPolicy::kStamps;
  double window = 10.0;  ///< s of receipt time over which "estimate" takes its minimum, > 0
  /// s; a skew |receipt − stamp| beyond it is not learnt from, and InputTimeline refuses the
  /// stamp (implausible) under "receipt" and "estimate"
  double max_offset = 60.0;
  /// s/s, in [0, 1]: how fast the "estimate" offset may move (both ways) once it has one, so
  /// that a sender moving its stamps a little at a time cannot lead it, and a delay that grows
  /// stays visible as age. 1e-3 (1 ms a second) is ten times a crystal's drift.
  double max_drift_rate = 1e-3;
};

/// The skew s = receipt − stamp of one input's messages (ns; the clock offset plus the
/// transport delay), and the offset o a policy adds to a stamp: o = 0 ("stamps"), o = s of the
/// message itself ("receipt"), o = min s over the messages received in the last window
/// ("estimate": the offset plus the smallest delay seen; the delay beyond it stays visible as
/// age). The minimum is kept in 16 buckets of window/16 each: no allocation, O(16) a message.
/// Learns only from the messages it is told were accepted (accepted()), and from skews within
/// max_offset, so that a forged stamp cannot move the estimate far; before any, "estimate" uses
/// the message's own skew. After that the estimate moves towards the window's minimum by at
/// most max_drift_rate × the receipt time since the offset last used: |o(t) − o(t')| ≤
/// max_drift_rate |t − t'|. A sender whose clock steps is refused (future or stale) until its
/// InputTimeline starts afresh (its timeout) and takes the new skew as its first.
class StampCorrection {
 public:
  static constexpr int kBuckets = 16;

  /// @throws std::invalid_argument naming window or max_offset out of range
  explicit StampCorrection(const StampCorrectionOptions& options);

  /// The offset (ns) to add to @p stamp_ns, a message received at @p receipt_ns (both on their
  /// own clocks); 0 for a zero stamp (which stays refusable as such).
  std::int64_t offsetFor(std::int64_t stamp_ns, std::int64_t receipt_ns) const;

  /// A message stamped @p stamp_ns, received at @p receipt_ns, was accepted: learn its skew.
  /// With @p offset_ns (what offsetFor() gave it) the estimate's bounded drift starts from there.
  void accepted(std::int64_t stamp_ns, std::int64_t receipt_ns);
  void accepted(std::int64_t stamp_ns, std::int64_t receipt_ns, std::int64_t offset_ns);

  /// The latest accepted message's skew (s); NaN before one.
  double lastSkew() const { return last_skew_; }
  /// The window's smallest skew (s) at @p receipt_ns; NaN when the window holds none.
  double minimumSkew(std::int64_t receipt_ns) const;

  /// Forgets what it learnt (ROS time went back).
  void reset();

  const StampCorrectionOptions& options() const { return options_; }

 private:
  struct Bucket {
    std::int64_t index = std::numeric_limits<std::int64_t>::min();  ///< receipt / bucket length
    std::int64_t minimum = std::numeric_limits<std::int64_t>::max();
  };
  /// The window's smallest skew (ns) at @p receipt_ns; false when it holds none.
  bool minimum(std::int64_t receipt_ns, std::int64_t* skew) const;

  StampCorrectionOptions options_;
  std::int64_t bucket_ns_;
  std::int64_t max_offset_ns_;
  std::array<Bucket, kBuckets> buckets_{};
  double max_drift_rate_ = 1e-3;
  bool have_offset_ = false;    ///< "estimate": an offset was used for an accepted message
  std::int64_t offset_ns_ = 0;  ///< that offset
  std::int64_t offset_at_ = 0;  ///< and its message's receipt time
  double last_skew_ = std::numeric_limits<double>::quiet_NaN();
};

}  // namespace projection_collision_avoidance
