#pragma once

#include <exception>

#include <ros/ros.h>

#include "projection_collision_avoidance/ParameterError.hpp"

namespace projection_collision_avoidance {

/// main() of a node: builds Node(nh, private_nh) and spins. A parameter the node refuses is
/// logged as "invalid parameter <key>: <reason>" and ends the process with exit code 1; so does
/// any other exception (logged as "failed: <what>"), rather than an abort.
template <typename Node>
int runNode(int argc, char** argv, const char* name) {
  ros::init(argc, argv, name);
  ros::NodeHandle nh;
  ros::NodeHandle private_nh("~");
  try {
    Node node(nh, private_nh);
    ros::spin();
  } catch (const ParameterError& error) {
    ROS_FATAL_STREAM(ros::this_node::getName() << ": invalid parameter " << error.what());
    return 1;
  } catch (const std::exception& error) {
    ROS_FATAL_STREAM(ros::this_node::getName() << ": failed: " << error.what());
    return 1;
  }
  return 0;
}

}  // namespace projection_collision_avoidance
