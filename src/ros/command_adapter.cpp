#include "projection_collision_avoidance/ros/CommandAdapter.hpp"

#include "NodeMain.hpp"

int main(int argc, char** argv) {
  return projection_collision_avoidance::runNode<projection_collision_avoidance::CommandAdapter>(
      argc, argv, "command_adapter");
}
