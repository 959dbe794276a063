// load_nodelet TYPE MANAGER [ARGS...]: asks the nodelet manager MANAGER to load a nodelet of
// TYPE under this node's name, with this node's remappings and ARGS, and exits: 0 once loaded,
// 1 if the manager refuses. It waits for the manager as long as ROS runs.
//
// `nodelet load ... --no-bond` does the same but then stays alive as an idle ROS node until the
// launch ends; a platoon of N nodelets keeps N such processes, which together take a large part
// of a core on a small computer (doc/node_cpu.md). This one costs nothing once the nodelet runs.
// The manager keeps the nodelet until it ends itself.
#include <string>
#include <vector>

#include <nodelet/NodeletLoad.h>
#include <ros/ros.h>

int main(int argc, char** argv) {
  ros::init(argc, argv, "load_nodelet", ros::init_options::NoRosout);
  std::vector<std::string> args;
  ros::removeROSArgs(argc, argv, args);
  if (args.size() < 3) {
    ROS_FATAL("usage: load_nodelet TYPE MANAGER [ARGS...]");
    return 2;
  }
  // Its private namespace is the nodelet's: it reads no parameter.
  ros::NodeHandle nh;
  nodelet::NodeletLoad load;
  load.request.name = ros::this_node::getName();
  load.request.type = args[1];
  for (const auto& remap : ros::names::getRemappings()) {
    load.request.remap_source_args.push_back(remap.first);
    load.request.remap_target_args.push_back(remap.second);
  }
  load.request.my_argv.assign(args.begin() + 3, args.end());
  const std::string service = ros::names::resolve(args[2]) + "/load_nodelet";
  if (!ros::service::waitForService(service)) {
    return 1;  // shut down while waiting
  }
  if (!ros::service::call(service, load) || !load.response.success) {
    ROS_FATAL("%s: %s refused to load %s (see the manager's log)", load.request.name.c_str(),
              service.c_str(), load.request.type.c_str());
    return 1;
  }
  return 0;
}
