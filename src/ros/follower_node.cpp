#include "projection_collision_avoidance/ros/FollowerNode.hpp"

#include "NodeMain.hpp"

int main(int argc, char** argv) {
  return projection_collision_avoidance::runNode<projection_collision_avoidance::FollowerNode>(
      argc, argv, "follower_node");
}
