#pragma once

/// @file
/// The link that carries shared information (a target's acceleration) to the follower that looks
/// at it, as a sampled run (cf_sim) models it: a delay of whole control periods, a fixed latency,
/// messages lost at random, and the receiver holding the last value it got. doc/math.md,
/// "Platoons", equations (L1)-(L3).

#include <cstddef>
#include <cstdint>
#include <vector>

namespace projection_collision_avoidance {

/// Scenario section controller.leader_information.link. Without it (configured false) a follower
/// gets its target's acceleration of the same tick, as before the link existed.
struct LinkSpec {
  bool configured = false;  ///< the scenario has a link section
  int delay_periods = 0;    ///< k >= 0: whole control periods of delay
  double latency = 0.0;     ///< fixed latency (s) >= 0, added to the delay
  double dropout = 0.0;     ///< probability in [0, 1) that a message is lost
  std::uint64_t seed = 0;   ///< seed of the losses (the same seed, the same losses)

  /// Largest total delay D (periods): a sender keeps D + 1 values in flight.
  static constexpr int kMaxDelayPeriods = 10000;
  /// Largest latency (s), checked before it is converted to periods.
  static constexpr double kMaxLatency = 60.0;

  /// Total delay in control periods, (L1):  D = k + ceil(latency f - 1e-9),  f = control_rate
  /// (Hz). A message sent at tick j is read at the first tick at or after its arrival,
  /// t_j + k T + latency; an arrival within 1e-9 periods after a tick counts as on it.
  int totalDelayPeriods(double control_rate) const;

  /// Throws ParameterError naming controller.leader_information.link.delay_periods (a count
  /// outside [0, kMaxDelayPeriods]), .latency (not finite, negative, over kMaxLatency, or D over
  /// kMaxDelayPeriods at @p control_rate) or .dropout (outside [0, 1)). A control_rate that is
  /// not positive and finite skips the check of D (the controller design refuses it).
  void validate(double control_rate) const;

  /// True when the link changes anything: a delay, a latency or a loss probability.
  bool active() const {
    return configured && (delay_periods > 0 || latency > 0.0 || dropout > 0.0);
  }
};

/// The splitmix64 output function (S. Vigna): z = x + 0x9E3779B97F4A7C15, then
/// z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9, z = (z ^ (z >> 27)) * 0x94D049BB133111EB,
/// z ^ (z >> 31), all modulo 2^64.
std::uint64_t splitMix64(std::uint64_t x);

/// Whether the message sent at tick @p tick to follower @p receiver is lost, (L2):
///   lost  <=>  (splitMix64(splitMix64(seed) ^ (receiver << 40 | tick)) >> 11) 2^-53 < dropout.
/// A function of its arguments only: the same seed gives the same losses in any order of
/// evaluation, and each follower's link loses messages independently of the others'.
/// @param receiver follower index i, 0 .. 2^24 - 1
/// @param tick j >= 0, below 2^40
bool linkMessageLost(std::uint64_t seed, int receiver, long tick, double dropout);

/// What the receiving end of a link does with one message, for a link between processes (the
/// ROS link_relay) that must lose and delay exactly what the sampled run's SharedLink does.
struct LinkVerdict {
  long tick = 0;         ///< j = round(stamp f): the sender's control tick
  bool lost = false;     ///< (L2) for (receiver, j)
  double release = 0.0;  ///< s: stamp + D / f, when the receiver may read it (L1)
};

/// The verdict on a message stamped @p stamp s (the sender's tick time, >= 0) on the link to
/// follower @p receiver at @p control_rate f (Hz): j = round(stamp f), lost as (L2), released at
/// stamp + D / f with D = spec.totalDelayPeriods(f). A negative stamp counts as tick 0.
LinkVerdict judgeLinkMessage(const LinkSpec& spec, double control_rate, int receiver, double stamp);

/// The values in flight on the links of a formation and what each follower holds, (L3): at tick
/// k follower i reads the message its target sent at tick j = k - D; if j >= 0 and that message
/// is not lost (L2), it replaces the held value; the follower uses the held value, zero until a
/// first message arrives. With D = 0 the target must send() before its follower receive()s.
template <typename Vector>
class SharedLink {
 public:
  /// @param senders agents that send (0 the leader, i follower i)
  /// @param receivers followers that receive (1 .. receivers - 1 used)
  /// @param zero the value held before the first message
  SharedLink(const LinkSpec& spec, double control_rate, int senders, int receivers,
             const Vector& zero)
      : spec_(spec),
        delay_(spec.totalDelayPeriods(control_rate)),
        slots_(static_cast<std::size_t>(delay_) + 1),
        in_flight_(static_cast<std::size_t>(senders) * slots_, zero),
        held_(static_cast<std::size_t>(receivers), zero) {}

  /// Total delay D in periods.
  int delay() const { return delay_; }

  /// Puts @p value, sent by @p sender at @p tick, on the link.
  void send(int sender, long tick, const Vector& value) { slot(sender, tick) = value; }

  /// The value follower @p receiver uses at @p tick, from @p sender (its target), (L3).
  const Vector& receive(int receiver, int sender, long tick) {
    Vector& held = held_[static_cast<std::size_t>(receiver)];
    const long sent = tick - delay_;
    if (sent >= 0 && !linkMessageLost(spec_.seed, receiver, sent, spec_.dropout)) {
      held = slot(sender, sent);
    }
    return held;
  }

 private:
  Vector& slot(int sender, long tick) {
    return in_flight_[static_cast<std::size_t>(sender) * slots_ +
                      static_cast<std::size_t>(tick) % slots_];
  }

  LinkSpec spec_;
  int delay_;
  std::size_t slots_;
  std::vector<Vector> in_flight_;  // D + 1 values per sender, ring buffers
  std::vector<Vector> held_;       // per receiver
};

}  // namespace projection_collision_avoidance
