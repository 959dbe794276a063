#pragma once

#include <chrono>
#include <cstdint>
#include <string>

namespace projection_collision_avoidance {

/// Why an input message was refused. Logging is once per change of kind, so a kind must not
/// depend on anything a sender controls (its frame_id, its numbers).
enum class Rejection : std::uint8_t {
  kFrame,        ///< frame_id other than the required one
  kZeroStamp,    ///< stamp 0 (unset)
  kFuture,       ///< stamped more than max_future_stamp ahead of the receiver's clock
  kStale,        ///< older than max_age when it arrives
  kOutOfOrder,   ///< stamped before the last accepted message
  kRepeated,     ///< stamped exactly as the last accepted message
  kContent,      ///< wrong size, non-finite entries, wrong child frame (the caller's checks)
  kUnjudgeable,  ///< judging it failed (an exception while converting it)
  kPublisher,    ///< sent by another publisher than the one that holds the input
  kImplausible,  ///< stamped further from the receiver's clock than ~clock_skew/max_offset
};

/// "frame", "zero stamp", "future stamp", "stale", "out of order", "repeated stamp", "content",
/// "unjudgeable", "other publisher", "implausible stamp".
const char* toString(Rejection kind);

/// What an input guard admits: the header checks of one input topic.
struct InputGuardLimits {
  /// frame_id a message must carry, up to a leading slash (sameFrame()); "" accepts any
  std::string required_frame;
  double max_future_stamp = 0;  ///< s a stamp may lie ahead of the receiver's clock (offsets)
  double max_age = 0;           ///< s a message may be old when it arrives; <= 0: no limit
  /// A stamp not after the last accepted one is superseded, not refused: dropped, counted in
  /// superseded() and logged at most once per kSummaryPeriod. For streams of a sender's state
  /// (odometry, positions), where a message older than the latest carries nothing newer (a
  /// bridge that publishes from several threads, a bursty simulated clock); false: refused as
  /// out of order or repeated (the package's own measurements, broadcasts and commands).
  bool supersede_older = false;
};

/// Admission of the messages of one input topic, free of ROS: stamps are ns since the epoch
/// (`ros::Time::toNSec()`, which fits an int64 over the whole range of ros::Time), so no stamp
/// can overflow the arithmetic. It refuses zero stamps, stamps too far ahead of the receiver's
/// clock, messages stale on arrival, and stamps not after the last accepted one (a repeated stamp
/// included); it counts every refusal, and says when a refusal is worth a log line: when its kind
/// differs from the kind last logged (at most one such line per @ref kTransitionPeriod), and
/// every @ref kSummaryPeriod while refusals go on; each line gives the count since the line
/// before. Accepted messages in between do not make a refusal new. Texts a sender controls are
/// cut to @ref kMaxQuotedLength characters.
///
/// Ages are measured from the *effective* stamp of a message, min(stamp, receipt time): a stamp
/// ahead of the receiver's clock (within max_future_stamp) counts from its receipt, so an age is
/// never negative while the clock runs forward. When the receiver's clock jumps back, call
/// restartTimeline(): the inputs of the old timeline are forgotten (no age, so stale), while
/// everAccepted() still tells that the input was heard.
///
/// With InputGuardLimits::supersede_older, a message stamped at or before the last accepted one
/// is superseded instead: checkHeader() returns false without a refusal (lastSuperseded()), the
/// count superseded() grows, and a log line is due for the first one and then at most once per
/// @ref kSummaryPeriod, with the count since the line before. A stamp accepted ahead of the
/// clock supersedes the messages after it for at most max_future_stamp.
class InputGuard {
 public:
  /// Length to which a frame_id (or other text a sender controls) is cut when quoted (bytes).
  static constexpr std::size_t kMaxQuotedLength = 64;
  /// Length to which a reason is cut in logs and diagnostics (bytes).
  static constexpr std::size_t kMaxReasonLength = 256;
  /// Shortest interval between two log lines for a change of kind.
  static constexpr std::chrono::seconds kTransitionPeriod{1};
  /// Interval of the summary log line while refusals of the logged kind go on.
  static constexpr std::chrono::seconds kSummaryPeriod{60};
  using Clock = std::chrono::steady_clock;

  InputGuard() = default;
  /// @param topic the input's name in log lines
  /// @param clock time source of the log intervals (a test's own, or the steady clock)
  InputGuard(std::string topic, InputGuardLimits limits,
             Clock::time_point (*clock)() = &Clock::now);

  /// Checks a header at the receiver's time @p now_ns: frame, zero stamp, future, stale, order.
  /// Returns false after counting a refusal or, with supersede_older, a superseded message
  /// (lastSuperseded(); see takeLogLine()); on true the caller checks the content and calls
  /// accept() or reject().
  bool checkHeader(const std::string& frame_id, std::int64_t stamp_ns, std::int64_t now_ns);

  /// Counts a refusal of @p kind; @p detail (cut to kMaxReasonLength) says what was wrong.
  void reject(Rejection kind, const std::string& detail);

  /// Records an accepted message stamped @p stamp_ns, received at @p now_ns.
  void accept(std::int64_t stamp_ns, std::int64_t now_ns);

  /// The receiver's clock went back: forget the last accepted stamp (the order check starts
  /// afresh) and the age. Counts and everAccepted() are kept.
  void restartTimeline();

  /// A message was accepted on the current timeline.
  bool haveAccepted() const { return have_accepted_; }
  /// A message was accepted since start, on any timeline.
  bool everAccepted() const { return ever_accepted_; }
  /// Stamp of the last accepted message (ns), 0 before one.
  std::int64_t lastStamp() const { return last_stamp_ns_; }
  /// Age (s) at @p now_ns of the last accepted message, from its effective stamp; +infinity
  /// when there is none on this timeline.
  double ageAt(std::int64_t now_ns) const;

  /// Messages accepted since start.
  std::uint64_t accepted() const { return accepted_; }
  /// Refusals since start.
  std::uint64_t rejected() const { return rejected_; }
  /// Messages superseded since start (supersede_older: stamped at or before the last accepted).
  std::uint64_t superseded() const { return superseded_; }
  /// The latest checkHeader() returned false because its message was superseded.
  bool lastSuperseded() const { return last_superseded_; }
  /// Kind of the latest refusal (kContent before any).
  Rejection lastKind() const { return kind_; }
  /// Refusals of the current kind since it began.
  std::uint64_t rejectedOfKind() const { return run_length_; }
  /// The latest refusal ("kind: detail", bounded), "" once a message was accepted after it.
  const std::string& lastRejection() const { return last_rejection_; }

  /// The log line the latest refusal calls for, or "" (then nothing is due). Taking it clears it.
  std::string takeLogLine();

 private:
  std::string topic_;
  InputGuardLimits limits_;
  bool have_accepted_ = false;
  bool ever_accepted_ = false;
  std::int64_t last_stamp_ns_ = 0;
  std::int64_t effective_stamp_ns_ = 0;
  Clock::time_point (*clock_)() = &Clock::now;
  std::uint64_t accepted_ = 0;
  std::uint64_t rejected_ = 0;
  std::uint64_t superseded_ = 0;
  bool last_superseded_ = false;
  bool have_logged_superseded_ = false;
  Clock::time_point last_superseded_log_;
  std::uint64_t unlogged_superseded_ = 0;  ///< superseded since its last log line
  Rejection kind_ = Rejection::kContent;   ///< kind of the latest refusal
  std::uint64_t run_length_ = 0;           ///< refusals of kind_ in a row (accepts ignored)
  bool have_logged_ = false;
  Rejection logged_kind_ = Rejection::kContent;  ///< kind of the last log line
  Clock::time_point last_log_;
  std::uint64_t unlogged_ = 0;  ///< refusals since the last log line
  std::string last_rejection_;
  std::string log_line_;

  /// Counts a superseded message and sets the log line when one is due.
  void supersede();
};

/// @p text cut to @p length characters, with the original length appended when cut.
std::string boundedText(const std::string& text, std::size_t length);

}  // namespace projection_collision_avoidance
