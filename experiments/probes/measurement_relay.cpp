/// A bare roscpp relay, the baseline of the latency measurement
/// (experiments/probes/latency.launch): subscribes `input` (RelativeMeasurement, queue 10,
/// TCP_NODELAY) and republishes each message unchanged on `output`. Nothing else: no parameters, no
/// checks, one thread (ros::spin()).

#include <ros/ros.h>

#include "projection_collision_avoidance/RelativeMeasurement.h"

namespace {

ros::Publisher output;

void relay(const projection_collision_avoidance::RelativeMeasurement::ConstPtr& msg) {
  output.publish(msg);
}

}  // namespace

int main(int argc, char** argv) {
  ros::init(argc, argv, "measurement_relay");
  ros::NodeHandle nh;
  output = nh.advertise<projection_collision_avoidance::RelativeMeasurement>("output", 10);
  ros::Subscriber input = nh.subscribe("input", 10, relay, ros::TransportHints().tcpNoDelay());
  ros::spin();
  output.shutdown();
  return 0;
}
