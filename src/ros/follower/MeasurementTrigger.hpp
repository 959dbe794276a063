#pragma once

#include <cstdint>

#include "projection_collision_avoidance/cycle/FollowerCycle.hpp"

#include "follower/FollowerOutputs.hpp"

namespace projection_collision_avoidance {

/// ~trigger measurement: the step that answers each accepted measurement, run in the
/// measurement's callback as soon as FollowerInputs has written it to the cycle, and published
/// at once. ROS time is read again once the cycle has latched the other inputs (their callbacks
/// may run on other threads), so that none of them counts as received after the step's time.
class MeasurementTrigger {
 public:
  /// @param cycle the control cycle; @p outputs where the step goes; both outlive this object
  MeasurementTrigger(FollowerCycle* cycle, FollowerOutputs* outputs)
      : cycle_(cycle), outputs_(outputs) {}

  /// The step for the measurement just accepted, @p skipped periods after the one before it.
  void onAccepted(std::uint32_t skipped);

 private:
  FollowerCycle* cycle_;
  FollowerOutputs* outputs_;
  FollowerCycleOutput output_;  ///< the callback's thread only (roscpp serialises it)
};

}  // namespace projection_collision_avoidance
