/// The nodes as nodelets: each owns the same class the stand-alone node runs.

#include <exception>
#include <iostream>
#include <memory>

#include <nodelet/nodelet.h>
#include <pluginlib/class_list_macros.hpp>

#include "projection_collision_avoidance/core/ParameterError.hpp"
#include "projection_collision_avoidance/ros/CommandAdapter.hpp"
#include "projection_collision_avoidance/ros/FollowerNode.hpp"
#include "projection_collision_avoidance/ros/LeaderNode.hpp"
#include "projection_collision_avoidance/ros/LinkRelay.hpp"
#include "projection_collision_avoidance/ros/PlantNode.hpp"
#include "projection_collision_avoidance/scenario/ScenarioLoader.hpp"

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

class FollowerNodelet : public NodeletOf<FollowerNode> {};
class LeaderNodelet : public NodeletOf<LeaderNode> {};
class PlantNodelet : public NodeletOf<PlantNode> {};
class LinkRelayNodelet : public NodeletOf<LinkRelay> {};
class CommandAdapterNodelet : public NodeletOf<CommandAdapter> {};

}  // namespace projection_collision_avoidance

PLUGINLIB_EXPORT_CLASS(projection_collision_avoidance::FollowerNodelet, nodelet::Nodelet)
PLUGINLIB_EXPORT_CLASS(projection_collision_avoidance::LeaderNodelet, nodelet::Nodelet)
PLUGINLIB_EXPORT_CLASS(projection_collision_avoidance::PlantNodelet, nodelet::Nodelet)
PLUGINLIB_EXPORT_CLASS(projection_collision_avoidance::LinkRelayNodelet, nodelet::Nodelet)
PLUGINLIB_EXPORT_CLASS(projection_collision_avoidance::CommandAdapterNodelet, nodelet::Nodelet)
