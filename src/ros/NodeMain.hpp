#pragma once

#include <exception>
#include <iostream>
#include <string>

#include <ros/ros.h>

#include "projection_collision_avoidance/configuration/ConfigurationLoader.hpp"
#include "projection_collision_avoidance/core/ParameterError.hpp"

namespace projection_collision_avoidance {

/// Logs @p line as fatal, or writes it to stderr once roscpp shuts down (SIGINT, rosnode kill):
/// its logging is off from then on.
inline void reportFatal(const std::string& line) {
  if (ros::isShuttingDown() || !ros::ok()) {
    std::cerr << line << std::endl;
  } else {
    ROS_FATAL_STREAM(line);
  }
}

/// main() of a node: builds Node(nh, private_nh) and spins. A parameter the node refuses is
/// logged as "invalid parameter <key>: <reason>" and ends the process with exit code 1; so does
/// any other exception (logged as "failed: <what>"), rather than an abort, and a scenario load
/// cancelled by SIGINT ("not started: ~scenario: loading cancelled at ...").
template <typename Node>
int runNode(int argc, char** argv, const char* name) {
  ros::init(argc, argv, name);
  ros::NodeHandle nh;
  ros::NodeHandle private_nh("~");
  try {
    Node node(nh, private_nh);
    ros::spin();
  } catch (const ScenarioLoadCancelled& cancelled) {
    reportFatal(ros::this_node::getName() + ": not started: " + cancelled.what());
    return 1;
  } catch (const ParameterError& error) {
    reportFatal(ros::this_node::getName() + ": invalid parameter " + error.what());
    return 1;
  } catch (const std::exception& error) {
    reportFatal(ros::this_node::getName() + ": failed: " + error.what());
    return 1;
  }
  return 0;
}

}  // namespace projection_collision_avoidance
