#pragma once

#include <cstdint>

namespace projection_collision_avoidance {

/// Paces the steps of the measurement trigger by the measurements' stamps, free of ROS: a token
/// bucket whose credit (in control periods T) accrues at 1/T per second of stamp time, capped at
/// one period; a measurement may step while the credit is at least half a period, and its step
/// spends one (the credit may then fall to -1/2). The first measurement steps.
///
/// So whatever a sender does, the loop steps no faster than the control rate: over any window
/// of W s of stamps, at most W / T + 1.5 steps (at most 1 of credit at its start, at least -1/2
/// at its end, W / T accrued in between); copies of one measurement stamped microseconds apart
/// step once. A sensor at the control rate loses no step even with its stamps T/4 early or late
/// (the credit before a step then stays at least 1/2), nor one slightly slower or faster; after
/// a gap the first measurement steps at once, and the cap leaves no credit for a burst after it.
/// Stamps that go back accrue nothing. Integer nanoseconds, T rounded up to a whole nanosecond
/// (never faster than the rate). Allocates nothing.
class StepPacer {
 public:
  /// @param period the control period T (s), > 0 (std::invalid_argument otherwise)
  explicit StepPacer(double period);

  /// Whether the measurement stamped @p stamp_ns (ns, on the receiver's clock) runs a step; when
  /// it does, its period of credit is spent. Either way the stamp is the one the next accrues
  /// from.
  bool admit(std::int64_t stamp_ns);

  /// Forgets the stamps (time went back): the next measurement steps.
  void reset() { started_ = false; }

  /// T in whole nanoseconds (rounded up).
  std::int64_t periodNs() const { return period_ns_; }
  /// The credit now, in ns of stamp time (between -periodNs() / 2 and periodNs() once started).
  std::int64_t creditNs() const { return credit_ns_; }

 private:
  std::int64_t period_ns_;
  std::int64_t credit_ns_ = 0;
  std::int64_t last_stamp_ns_ = 0;
  bool started_ = false;
};

}  // namespace projection_collision_avoidance
