#include "follower/MeasurementTrigger.hpp"

#include <ros/time.h>

#include "projection_collision_avoidance/ros/InputAdmission.hpp"

namespace projection_collision_avoidance {

void MeasurementTrigger::onAccepted(std::uint32_t skipped) {
  cycle_->stepOnMeasurement([] { return nanosecondsOf(ros::Time::now()); }, skipped, &output_);
  outputs_->publish(output_);
}

}  // namespace projection_collision_avoidance
