#include "projection_collision_avoidance/ros/LinkRelay.hpp"

#include "NodeMain.hpp"

int main(int argc, char** argv) {
  return projection_collision_avoidance::runNode<projection_collision_avoidance::LinkRelay>(
      argc, argv, "link_relay");
}
