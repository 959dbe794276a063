#include "projection_collision_avoidance/ros/PlantNode.hpp"

#include <memory>

#include "plant/PlantWorld.hpp"

namespace projection_collision_avoidance {

PlantNode::PlantNode(ros::NodeHandle nh, ros::NodeHandle private_nh)
    : world_(std::make_unique<PlantWorld>(nh, private_nh)) {}

PlantNode::~PlantNode() = default;

}  // namespace projection_collision_avoidance
