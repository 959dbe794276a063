#pragma once

#include <memory>

#include <ros/ros.h>

namespace projection_collision_avoidance {

class PlantWorld;

/// The simulated plant as a node: the leader and the followers of the scenario's formation as
/// double integrators, their commands in, odometry, tf, relative measurements (with the sensor
/// faults of ~measurement_*), markers and, with ~publish_clock, /clock out. The parts:
/// PlantWorld (agents, commands, what each tick publishes), MeasurementChannels (the sensor's
/// faults; no ROS) and PlantClock (when ticks are due).
class PlantNode {
 public:
  /// @throws ParameterError naming the parameter when the scenario or an option is invalid
  PlantNode(ros::NodeHandle nh, ros::NodeHandle private_nh);
  ~PlantNode();
  PlantNode(const PlantNode&) = delete;
  PlantNode& operator=(const PlantNode&) = delete;

 private:
  std::unique_ptr<PlantWorld> world_;
};

}  // namespace projection_collision_avoidance
