#pragma once

/// @file
/// The velocity commands a vehicle was sent, with when and by how much each changed the command,
/// so that a measurement taken before some of them can be brought up to date (doc/vehicles.md).

#include <cstddef>
#include <vector>

#include "projection_collision_avoidance/vehicle/AxisVector.hpp"

namespace projection_collision_avoidance {

/// One velocity command as sent.
struct SentCommand {
  double time = 0.0;    ///< s, when it was sent
  AxisVector velocity;  ///< m/s, the command
  /// m/s, the velocity change it asks of the vehicle over a period: a T when nothing limited it
  /// (what it added to its anchor, a h, times T / h)
  AxisVector increment;
};

/// The last `capacity` velocity commands, oldest first, in a ring allocated once: push(),
/// lookups and sums allocate nothing. Times are kept non-decreasing: a command sent before the
/// newest one (time went back) clears the history first.
class CommandHistory {
 public:
  /// @param capacity commands kept, ≥ 1
  /// @param axes 1 to 3
  CommandHistory(std::size_t capacity, int axes);

  /// Appends a command sent at @p time (s); the oldest is dropped when full. Ignored if any
  /// value is not finite or not of the history's axes.
  void push(double time, const AxisVector& velocity, const AxisVector& increment);

  /// Replaces the newest command by what was actually sent (@p velocity), its increment
  /// changed by @p scale times as much (T / h). Ignored when empty, not finite or of the wrong
  /// size.
  void replaceNewest(const AxisVector& velocity, double scale = 1.0);

  /// The command in force just before @p time (s): the last one sent before it. (A velocity
  /// measured at t shows at most the commands sent before t: one sent at t was made after it.)
  /// @return false (velocity untouched) when no kept command was sent before then
  bool commandBefore(double time, AxisVector* velocity) const;

  /// Σ of the increments of the kept commands sent in [@p from, @p before) (s): the velocity
  /// change the commands of that interval asked for.
  AxisVector incrementBetween(double from, double before) const;

  /// Forgets every command.
  void clear();

  /// The @p i-th newest kept command (0 the newest), i < size().
  const SentCommand& fromNewest(std::size_t i) const { return at(size_ - 1 - i); }

  std::size_t size() const { return size_; }
  std::size_t capacity() const { return ring_.size(); }
  int axes() const { return axes_; }

 private:
  /// The i-th kept command, 0 the oldest.
  const SentCommand& at(std::size_t i) const { return ring_[(head_ + i) % ring_.size()]; }

  std::vector<SentCommand> ring_;
  std::size_t head_ = 0;  ///< index of the oldest
  std::size_t size_ = 0;
  int axes_;
};

}  // namespace projection_collision_avoidance
