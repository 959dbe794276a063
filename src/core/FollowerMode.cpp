#include "projection_collision_avoidance/core/FollowerMode.hpp"

namespace projection_collision_avoidance {

FollowerMode selectFollowerMode(const FollowerInputAges& ages, const FollowerTimeouts& timeouts) {
  if (!ages.have_measurement) {
    return FollowerMode::kWaiting;
  }
  // Written so that a NaN age counts as stale.
  if (!(ages.measurement_age <= timeouts.measurement)) {
    return FollowerMode::kMeasurementLost;
  }
  if (ages.have_leader && !(ages.leader_age <= timeouts.leader)) {
    return FollowerMode::kLeaderLost;
  }
  return FollowerMode::kTracking;
}

const char* toString(FollowerMode mode) {
  switch (mode) {
    case FollowerMode::kWaiting:
      return "waiting";
    case FollowerMode::kTracking:
      return "tracking";
    case FollowerMode::kLeaderLost:
      return "leader_lost";
    case FollowerMode::kMeasurementLost:
      return "measurement_lost";
  }
  return "unknown";
}

}  // namespace projection_collision_avoidance
