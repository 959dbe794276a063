#pragma once

/// @file
/// A node's class run as a nodelet (src/ros/Nodelets.cpp, src/ros/sim/SimNodelets.cpp).

#include <exception>
#include <iostream>
#include <memory>

#include <nodelet/nodelet.h>

#include "projection_collision_avoidance/configuration/ConfigurationLoader.hpp"
#include "projection_collision_avoidance/core/ParameterError.hpp"

namespace projection_collision_avoidance {

/// Runs Node(node handle, private node handle) inside a nodelet manager. A refused parameter is
/// logged with its key, any other failure with its message, and the load fails (the manager's
/// process is not ended). A scenario load cancelled by the manager's shutdown is reported on
/// stderr, roscpp's logging being off by then.
template <typename Node>
class NodeletOf : public nodelet::Nodelet {
 private:
  void onInit() override {
    try {
      node_ = std::make_unique<Node>(getNodeHandle(), getPrivateNodeHandle());
    } catch (const ScenarioLoadCancelled& cancelled) {
      std::cerr << getName() << ": not started: " << cancelled.what() << std::endl;
      throw;
    } catch (const ParameterError& error) {
      NODELET_FATAL_STREAM(getName() << ": invalid parameter " << error.what());
      throw;
    } catch (const std::exception& error) {
      NODELET_FATAL_STREAM(getName() << ": failed: " << error.what());
      throw;
    }
  }

  std::unique_ptr<Node> node_;
};

}  // namespace projection_collision_avoidance
