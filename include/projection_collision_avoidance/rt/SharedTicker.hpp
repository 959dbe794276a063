#pragma once

/// @file
/// Periodic calls that many members of one process share: one thread per period runs every
/// member's call in turn at each deadline. For a nodelet manager holding many followers at one
/// control rate: one wake-up per period for all of them, where a thread each costs one per
/// follower (on a VM a wake-up costs tens of µs of CPU, more than a follower's tick). No ROS.

#include <chrono>
#include <cstdint>
#include <memory>
#include <string>

#include "projection_collision_avoidance/rt/PeriodicThread.hpp"

namespace projection_collision_avoidance {

class SharedTickerGroup;

/// A member's place in the group of its period. Its call runs at every deadline of the group's
/// PeriodicThread (no real-time priority), after the calls of the members that joined before it,
/// with PeriodicTick::actual the time its own call starts (so a member's delay counts the calls
/// before it) and the group's deadline, index and skipped deadlines. The deadlines lie on the
/// grid k * period of CLOCK_MONOTONIC (PeriodicThread's phase 0). Destroying it leaves the
/// group: it waits for a running round, and its call is not made again. The group's thread ends
/// when its last member leaves.
class SharedTicker {
 public:
  using Callback = PeriodicThread::Callback;

  /// Joins the group of @p period, starting its thread (named @p thread_name, at most 15
  /// characters kept) when this is the first member.
  /// @param callback must not throw, block, or join or leave a group
  /// @throws std::invalid_argument for a period <= 0 or no callback
  SharedTicker(std::chrono::nanoseconds period, const std::string& thread_name, Callback callback);
  ~SharedTicker();
  SharedTicker(const SharedTicker&) = delete;
  SharedTicker& operator=(const SharedTicker&) = delete;

  /// Deadlines the group's thread skipped since it started (its calls overran, or it woke late).
  std::uint64_t missedPeriods() const;
  /// Members of this member's group now (this one included).
  std::size_t groupSize() const;

 private:
  std::shared_ptr<SharedTickerGroup> group_;
  std::uint64_t id_ = 0;
};

}  // namespace projection_collision_avoidance
