/// cf_sim: runs a scenario's closed loop without ROS and prints one summary line.
/// Usage: cf_sim SCENARIO.yaml [--set key=value]... [--csv FILE]

#include <iostream>
#include <string>
#include <vector>

#include "projection_collision_avoidance/scenario/CfSimApp.hpp"

int main(int argc, char** argv) {
  // argv/argc is the C interface of main(); this is the one place it is turned into a range.
  // NOLINTNEXTLINE(cppcoreguidelines-pro-bounds-pointer-arithmetic)
  const std::vector<std::string> arguments(argv + 1, argv + argc);
  return projection_collision_avoidance::runCfSim(arguments, std::cout, std::cerr);
}
