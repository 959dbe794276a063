#include "projection_collision_avoidance/ros/PlantNode.hpp"

#include "NodeMain.hpp"

int main(int argc, char** argv) {
  return projection_collision_avoidance::runNode<projection_collision_avoidance::PlantNode>(
      argc, argv, "plant_node");
}
