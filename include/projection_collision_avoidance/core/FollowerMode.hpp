#pragma once

#include <cstdint>

namespace projection_collision_avoidance {

/// What a follower does at a control tick, given how old its inputs are.
enum class FollowerMode : std::uint8_t {
  kWaiting = 0,          ///< no measurement yet: no command
  kTracking = 1,         ///< fresh measurement (and leader broadcast, when one was heard)
  kLeaderLost = 2,       ///< fresh measurement, but the leader's broadcast went stale: the laws
                         ///< run on the measurement alone (u_1 unknown)
  kMeasurementLost = 3,  ///< stale measurement: the braking fallback
};

/// Ages of a follower's inputs at a tick and the timeouts that make them stale (s).
struct FollowerInputAges {
  bool have_measurement = false;  ///< a measurement was accepted since start
  double measurement_age = 0.0;   ///< now - stamp of the latest accepted measurement
  bool have_leader = false;       ///< a leader broadcast was accepted since start
  double leader_age = 0.0;        ///< now - stamp of the latest accepted broadcast
};

/// Timeouts (s) after which an input counts as stale; both > 0.
struct FollowerTimeouts {
  double measurement = 0.5;
  double leader = 0.5;
};

/// The mode for the given input ages: kWaiting before the first measurement, kMeasurementLost
/// once it is older than the measurement timeout (or not finite), kLeaderLost while the
/// measurement is fresh but a leader that was heard has gone silent for longer than the leader
/// timeout, kTracking otherwise. A stale input becomes fresh again with its next message.
FollowerMode selectFollowerMode(const FollowerInputAges& ages, const FollowerTimeouts& timeouts);

/// "waiting", "tracking", "leader_lost", "measurement_lost".
const char* toString(FollowerMode mode);

}  // namespace projection_collision_avoidance
