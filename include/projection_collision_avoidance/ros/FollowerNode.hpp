#pragma once

#include <mutex>
#include <string>

#include <Eigen/Core>
#include <boost/thread/recursive_mutex.hpp>
#include <diagnostic_updater/diagnostic_updater.h>
#include <dynamic_reconfigure/server.h>
#include <ros/ros.h>

#include "projection_collision_avoidance/FollowerConfig.h"
#include "projection_collision_avoidance/LeaderBroadcast.h"
#include "projection_collision_avoidance/RelativeMeasurement.h"
#include "projection_collision_avoidance/RuntimeFollowerController.hpp"
#include "projection_collision_avoidance/Scenario.hpp"

namespace projection_collision_avoidance {

/// The follower node's own options (besides the scenario), read once from its private namespace.
struct FollowerNodeOptions {
  double measurement_timeout = 0.5;   ///< s; older measurements are reported stale
  double leader_timeout = 0.5;        ///< s; older leader broadcasts are not used
  double max_future_stamp = 0.1;      ///< s; measurements stamped after now + this are refused
  bool use_leader_broadcast = false;  ///< subscribe to leader_broadcast for u_1
  std::string measurement_frame;      ///< required frame_id of measurements ("" = any)
  std::string follower_frame = "follower";  ///< frame of the command, status and markers
  double marker_rate = 10.0;                ///< Hz
};

/// ROS wrapper of RuntimeFollowerController: translates messages and time, nothing else.
///
/// Subscribes `relative_measurement` (RelativeMeasurement, x_1 - x_2) and, optionally,
/// `leader_broadcast` (LeaderBroadcast, for u_1). Every 1 / control_rate s (ROS time) it runs the
/// controller on y = C (x_1 - x_2 - d) and publishes `command` (geometry_msgs/AccelStamped),
/// `status` (FollowerStatus), `markers` (visualization_msgs/MarkerArray, in the follower's
/// frame) and diagnostics. dynamic_reconfigure changes the tracker switch, alpha, epsilon and the
/// tracker gain; a set the controller design refuses is rejected and the old one kept.
class FollowerNode {
 public:
  /// @throws ParameterError naming the parameter when the scenario or an option is invalid
  FollowerNode(ros::NodeHandle nh, ros::NodeHandle private_nh);

 private:
  void onMeasurement(const RelativeMeasurement::ConstPtr& msg);
  void onLeaderBroadcast(const LeaderBroadcast::ConstPtr& msg);
  void onControlTick(const ros::TimerEvent& event);
  void onReconfigure(FollowerConfig& config, uint32_t level);
  void publishStatus(const ros::Time& now, const Eigen::VectorXd& xi, bool fresh);
  void publishMarkers(const ros::Time& now, const Eigen::VectorXd& xi);
  void diagnose(diagnostic_updater::DiagnosticStatusWrapper& status);
  FollowerConfig configOf(const ControllerParameters& parameters) const;
  void rejectMeasurement(const std::string& why);

  ros::NodeHandle nh_;
  ros::NodeHandle private_nh_;
  FollowerNodeOptions options_;
  ControllerParameters parameters_;  ///< as currently in force (scenario + reconfigure)
  RuntimeFollowerController controller_;
  int axes_;

  std::mutex mutex_;  ///< guards everything below against concurrent callbacks (nodelets)
  Eigen::VectorXd relative_state_;  ///< latest accepted x_1 - x_2
  ros::Time measurement_stamp_;
  bool have_measurement_ = false;
  Eigen::VectorXd leader_input_;
  ros::Time leader_stamp_;
  bool have_leader_input_ = false;
  unsigned rejected_measurements_ = 0;
  std::string last_rejection_;
  bool last_tick_fresh_ = false;
  double last_xi_norm_ = 0.0;
  long ticks_ = 0;

  ros::Subscriber measurement_subscriber_;
  ros::Subscriber leader_subscriber_;
  ros::Publisher command_publisher_;
  ros::Publisher status_publisher_;
  ros::Publisher marker_publisher_;
  ros::Timer timer_;
  diagnostic_updater::Updater diagnostics_;
  FollowerConfig applied_config_;  ///< the reconfigure values in force
  boost::recursive_mutex reconfigure_mutex_;
  dynamic_reconfigure::Server<FollowerConfig> reconfigure_server_;
};

}  // namespace projection_collision_avoidance
