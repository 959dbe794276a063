#include "projection_collision_avoidance/ros/LeaderNode.hpp"

#include "NodeMain.hpp"

int main(int argc, char** argv) {
  return projection_collision_avoidance::runNode<projection_collision_avoidance::LeaderNode>(
      argc, argv, "leader_node");
}
