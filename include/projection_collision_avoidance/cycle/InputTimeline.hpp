#pragma once

#include <atomic>
#include <cstdint>
#include <limits>
#include <string>
#include <string_view>
#include <utility>

#include "projection_collision_avoidance/cycle/InputGuard.hpp"
#include "projection_collision_avoidance/cycle/StampCorrection.hpp"
#include "projection_collision_avoidance/cycle/TimeJumpWatch.hpp"

namespace projection_collision_avoidance {

/// The age (s) of an input when there is none on the current timeline: +infinity, in the
/// status message and in the diagnostics alike (a stale input is older than any timeout).
inline constexpr double kNoInputAge = std::numeric_limits<double>::infinity();

/// Age (s) at @p at_ns of an input stamped @p stamp_ns and received at @p receipt_ns (ns since
/// the epoch): from the earlier of the two, so that a stamp ahead of the receiver's clock counts
/// from its receipt and an age is never negative while the clock runs forward. The one age
/// function of every input (InputTimeline::age(), FollowerCycle).
inline double inputAge(std::int64_t at_ns, std::int64_t stamp_ns, std::int64_t receipt_ns) {
  return 1e-9 * static_cast<double>(at_ns - (stamp_ns < receipt_ns ? stamp_ns : receipt_ns));
}

/// What an InputTimeline admits, and on which clock it reads the stamps.
struct InputTimelineOptions {
  InputGuardLimits limits;            ///< the header checks (frame, future, stale)
  StampCorrectionOptions correction;  ///< ~clock_skew; by default the stamps as they are
  /// checkHeader() watches the receiver's clock and restarts the timeline when it goes back;
  /// false: the owner calls restart() itself (the plant, whose clock reports its own jumps).
  bool watch_time = true;
  /// s, the input's timeout; 0: limits.max_age when it is > 0, else 1 s. A publisher holds the
  /// input until it has not been heard for this long; a timeline whose every message is refused
  /// for this long after its latest acceptance starts afresh.
  double timeout = 0.0;
};

/// One input topic's timeline, free of ROS (stamps and times in ns since the epoch): the
/// admission of its messages in one sequence, and what the rest of the node reads about them.
///
/// checkHeader() notes the receiver's time (a jump back restarts the timeline: noteTime()), puts
/// the stamp on the receiver's clock (the offset of StampCorrection, ~clock_skew/policy) and
/// judges the header at the receiver's time moved by that offset (InputGuard: frame, zero stamp,
/// future, stale, order on the raw stamps). Before any of that it applies the rules that keep one
/// message or one sender from taking the input (doc/boundary.md, "One sender, one timeline"):
///  - one publisher at a time: the first publisher heard holds the input; another publisher's
///    messages are refused (kPublisher) and counted (foreignMessages()) until the holder has not
///    been heard for the timeout; then the next one heard takes the input and the timeline
///    starts afresh (its order and offset are the new publisher's);
///  - under ~clock_skew/policy receipt and estimate a raw stamp further than max_offset from the
///    receiver's clock is refused (kImplausible) before it can touch the order or the offset;
///  - a timeline that has refused every message for longer than the timeout since its latest
///    acceptance (a stamp accepted far ahead that locks the order, a sender's clock that
///    stepped) starts afresh (restarts()): it forgets its order and offset, not the age.
/// The caller then checks and converts the content, and
/// calls reject() or accept(); accept() returns the stamp on the receiver's clock, never before
/// the one accepted before on this timeline (an estimated offset may shrink). The stamp and
/// receipt time of the latest accepted message, the refusal count and the latest skew are
/// atomics that any thread may read; everything else belongs to the input's thread (one caller
/// at a time). age() is the one age of the input, reported alike by status and diagnostics.
class InputTimeline {
 public:
  /// Receipt time of "nothing accepted on this timeline".
  static constexpr std::int64_t kNone = -1;
  /// How long (ns) after another publisher's latest message the diagnostics report it (ERROR).
  static constexpr std::int64_t kForeignReportNs = 10000000000;

  InputTimeline() = default;
  /// @param topic the input's name in log lines
  /// @param clock time source of the log intervals (a test's own, or the steady clock)
  /// @throws std::invalid_argument for correction options out of range (StampCorrection)
  InputTimeline(std::string topic, const InputTimelineOptions& options,
                InputGuard::Clock::time_point (*clock)() = &InputGuard::Clock::now);
  /// A timeline of stamps as they are (no correction) that watches the receiver's clock.
  InputTimeline(std::string topic, const InputGuardLimits& limits)
      : InputTimeline(std::move(topic), InputTimelineOptions{limits, {}, true}) {}
  /// Moves a timeline no other thread reads yet (into a container, say).
  InputTimeline(InputTimeline&& other) noexcept;
  InputTimeline& operator=(InputTimeline&& other) noexcept;

  /// Notes the receiver's time @p now_ns; when it went back, restarts the timeline (restart())
  /// and returns true, once per jump.
  bool noteTime(std::int64_t now_ns);

  /// Judges a header (frame_id @p frame_id, stamp @p stamp_ns) received at @p now_ns: notes
  /// the time (with watch_time), takes the offset for the stamp, then the InputGuard checks at
  /// now − offset. False after counting a refusal (guard().lastKind(), takeLogLine()) or a
  /// superseded message (guard().lastSuperseded()); on true the caller checks the content and
  /// calls accept() or reject().
  /// @p publisher names the message's sender (roscpp's caller id); "" is any sender (a message
  /// handed over within the node), to which the one-publisher rule does not apply.
  bool checkHeader(const std::string& frame_id, std::int64_t stamp_ns, std::int64_t now_ns,
                   std::string_view publisher = {});

  /// Takes a message without a header (geometry_msgs/Twist, say) received at @p now_ns: notes
  /// the time (with watch_time); its stamp is its receipt, so there is no header to judge, and
  /// messages received at one time (a clock that stands still) are not out of order. The caller
  /// checks the content and calls accept() (whose stamp still lies after the one before) or
  /// reject().
  /// False after refusing it as another publisher's (kPublisher; see checkHeader()).
  bool checkReceipt(std::int64_t now_ns, std::string_view publisher = {});

  /// Counts a refusal of @p kind of the message being judged; @p detail says what was wrong.
  void reject(Rejection kind, const std::string& detail);

  /// Accepts the message last passed to checkHeader(): records it (order, skew, age).
  /// @return its stamp on the receiver's clock (ns): stamp + offset, and on this timeline at
  ///         least 1 ns after the one accepted before
  std::int64_t accept();

  /// The receiver's clock went back: forgets the old timeline (the order check, the learnt
  /// offset, the monotone stamp, the age). Counts and guard().everAccepted() are kept.
  void restart();

  /// The offset (ns) added to the stamp of the message last passed to checkHeader().
  std::int64_t offset() const { return offset_ns_; }

  /// The input's age (s) at @p now_ns: inputAge() of the latest accepted message; kNoInputAge
  /// (+infinity) when none was accepted on this timeline, or it was received after @p now_ns
  /// (an older timeline). Any thread.
  double age(std::int64_t now_ns) const;
  /// Receipt time (ns) of the latest accepted message on this timeline; kNone before one.
  /// Any thread.
  std::int64_t receipt() const { return receipt_ns_.load(std::memory_order_acquire); }
  /// Stamp (ns, on the receiver's clock, as accept() returned it) of the latest accepted
  /// message; meaningful while receipt() is not kNone. Any thread.
  std::int64_t stamp() const { return stamp_ns_.load(std::memory_order_relaxed); }
  /// Refusals since start. Any thread.
  std::uint64_t rejected() const { return rejected_.load(std::memory_order_relaxed); }
  /// Messages superseded since start (InputGuardLimits::supersede_older), not refusals. Any
  /// thread.
  std::uint64_t superseded() const { return superseded_.load(std::memory_order_relaxed); }
  /// The latest accepted message's skew, receipt − stamp (s, the raw stamp); NaN before one.
  /// Any thread.
  double skew() const { return skew_.load(std::memory_order_relaxed); }
  /// Messages refused since start because another publisher held the input. Any thread.
  std::uint64_t foreignMessages() const { return foreign_.load(std::memory_order_relaxed); }
  /// Receipt time (ns) of the latest such message; kNone before one. Any thread.
  std::int64_t foreignHeard() const { return foreign_heard_ns_.load(std::memory_order_relaxed); }
  /// Times the input passed to another publisher after its holder went quiet. Any thread.
  std::uint64_t handovers() const { return handovers_.load(std::memory_order_relaxed); }
  /// Times the timeline started afresh after refusing everything for its timeout. Any thread.
  std::uint64_t restarts() const { return restarts_.load(std::memory_order_relaxed); }
  /// The publisher that holds the input ("" before one; input's thread).
  const std::string& holder() const { return holder_; }
  /// The timeout (s) in force (InputTimelineOptions::timeout resolved).
  double timeout() const { return 1e-9 * static_cast<double>(timeout_ns_); }

  /// The admission's verdicts, counts and reasons (input's thread).
  const InputGuard& guard() const { return guard_; }
  /// The jumps back of the receiver's clock seen by noteTime().
  const TimeJumpWatch& jumps() const { return jumps_; }
  /// The log line the latest refusal calls for, or "" (InputGuard::takeLogLine()).
  std::string takeLogLine() { return guard_.takeLogLine(); }

 private:
  /// Capacity reserved for the holder's name, so that taking a name allocates nothing.
  static constexpr std::size_t kHolderCapacity = 256;
  /// checkHeader() after noting the time.
  bool judgeHeader(const std::string& frame_id, std::int64_t stamp_ns, std::int64_t now_ns,
                   std::string_view publisher);
  /// The one-publisher rule: true when @p publisher may be judged at @p now_ns.
  bool admitPublisher(std::string_view publisher, std::int64_t now_ns);
  /// Forgets the order and the offset (a new holder, or a timeline locked out), not the age.
  void startAfresh(std::int64_t now_ns);
  /// Notes a refusal of the message being judged for the lock-out rule.
  void noteRefusal();

  InputGuard guard_;
  StampCorrection correction_{StampCorrectionOptions{}};
  TimeJumpWatch jumps_;
  bool watch_time_ = true;
  std::int64_t timeout_ns_ = 1000000000;
  bool check_plausible_ = false;    ///< "receipt" and "estimate": refuse stamps beyond
  std::int64_t max_offset_ns_ = 0;  ///< the implausible-stamp bound
  std::string holder_;
  std::int64_t holder_heard_ns_ = 0;
  bool renew_holder_ = false;        ///< restart(): the holder's next hearing is dated then
  std::int64_t quiet_since_ns_ = 0;  ///< the latest acceptance, or the start afresh
  bool refused_since_ = false;       ///< a message was refused since quiet_since_ns_
  // The message being judged.
  std::int64_t raw_ns_ = 0;
  std::int64_t now_ns_ = 0;
  std::int64_t offset_ns_ = 0;
  // Read by other threads.
  std::atomic<std::int64_t> stamp_ns_{0};
  std::atomic<std::int64_t> receipt_ns_{kNone};
  std::atomic<std::uint64_t> rejected_{0};
  std::atomic<std::uint64_t> superseded_{0};
  std::atomic<double> skew_{std::numeric_limits<double>::quiet_NaN()};
  std::atomic<std::uint64_t> foreign_{0};
  std::atomic<std::int64_t> foreign_heard_ns_{kNone};
  std::atomic<std::uint64_t> handovers_{0};
  std::atomic<std::uint64_t> restarts_{0};
};

}  // namespace projection_collision_avoidance
