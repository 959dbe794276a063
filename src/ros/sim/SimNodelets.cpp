/// The simulation's nodes as nodelets (plant, leader, link relay): each owns the same class the
/// stand-alone node runs.

#include <pluginlib/class_list_macros.hpp>

#include "projection_collision_avoidance/ros/LeaderNode.hpp"
#include "projection_collision_avoidance/ros/LinkRelay.hpp"
#include "projection_collision_avoidance/ros/PlantNode.hpp"

#include "NodeletOf.hpp"

namespace projection_collision_avoidance {

class LeaderNodelet : public NodeletOf<LeaderNode> {};
class PlantNodelet : public NodeletOf<PlantNode> {};
class LinkRelayNodelet : public NodeletOf<LinkRelay> {};

}  // namespace projection_collision_avoidance

PLUGINLIB_EXPORT_CLASS(projection_collision_avoidance::LeaderNodelet, nodelet::Nodelet)
PLUGINLIB_EXPORT_CLASS(projection_collision_avoidance::PlantNodelet, nodelet::Nodelet)
PLUGINLIB_EXPORT_CLASS(projection_collision_avoidance::LinkRelayNodelet, nodelet::Nodelet)
