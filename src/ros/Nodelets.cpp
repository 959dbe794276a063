/// The follower's and the vehicle adapter's nodes as nodelets: each owns the same class the
/// stand-alone node runs. The simulation's nodelets are in sim/SimNodelets.cpp, a library of their
/// own, so that loading these links no simulation code.

#include <pluginlib/class_list_macros.hpp>

#include "projection_collision_avoidance/ros/CommandAdapter.hpp"
#include "projection_collision_avoidance/ros/FollowerNode.hpp"

#include "NodeletOf.hpp"

namespace projection_collision_avoidance {

class FollowerNodelet : public NodeletOf<FollowerNode> {};
class CommandAdapterNodelet : public NodeletOf<CommandAdapter> {};

}  // namespace projection_collision_avoidance

PLUGINLIB_EXPORT_CLASS(projection_collision_avoidance::FollowerNodelet, nodelet::Nodelet)
PLUGINLIB_EXPORT_CLASS(projection_collision_avoidance::CommandAdapterNodelet, nodelet::Nodelet)
