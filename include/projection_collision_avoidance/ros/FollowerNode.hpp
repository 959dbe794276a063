#pragma once

#include <cstdint>
#include <memory>
#include <mutex>
#include <string>

#include <Eigen/Core>
#include <boost/thread/recursive_mutex.hpp>
#include <diagnostic_updater/diagnostic_updater.h>
#include <dynamic_reconfigure/server.h>
#include <nav_msgs/Odometry.h>
#include <ros/callback_queue.h>
#include <ros/ros.h>

#include "projection_collision_avoidance/FollowerConfig.h"
#include "projection_collision_avoidance/FollowerMode.hpp"
#include "projection_collision_avoidance/Formation.hpp"
#include "projection_collision_avoidance/LeaderBroadcast.h"
#include "projection_collision_avoidance/RelativeMeasurement.h"
#include "projection_collision_avoidance/RuntimeFollowerController.hpp"
#include "projection_collision_avoidance/Scenario.hpp"
#include "projection_collision_avoidance/ros/InputAdmission.hpp"
#include "projection_collision_avoidance/ros/InputGuard.hpp"
#include "projection_collision_avoidance/ros/RealtimeLoop.hpp"
#include "projection_collision_avoidance/ros/RosParameters.hpp"

namespace projection_collision_avoidance {

/// What runs the follower's control steps (~trigger).
enum class ControlTrigger : std::uint8_t {
  kTimer,        ///< "timer": a timer at control_rate, on the latest accepted measurement
  kMeasurement,  ///< "measurement": each accepted measurement, at once, stamped with its stamp
};

/// "timer" or "measurement".
const char* toString(ControlTrigger trigger);

/// What runs the follower's fixed-rate control tick (~control_loop).
enum class ControlLoop : std::uint8_t {
  kTimer,   ///< "timer": a ros::Timer on a callback queue and spinner thread of its own
  kThread,  ///< "thread": a PeriodicThread sleeping to absolute CLOCK_MONOTONIC deadlines
};

/// "timer" or "thread".
const char* toString(ControlLoop loop);

/// Highest ~control_priority (SCHED_FIFO's highest priority on Linux).
constexpr int kMaxControlPriority = 99;

/// The follower node's own options (besides the scenario), read once from its private namespace.
struct FollowerNodeOptions {
  double measurement_timeout = 0.5;    ///< s; an older measurement puts the follower in fallback
  double leader_timeout = 0.5;         ///< s; an older leader broadcast is not used
  double max_future_stamp = 0.1;       ///< s; inputs stamped after now + this are refused
  bool use_leader_broadcast = false;   ///< use u_1 from leader_broadcast (always monitored)
  std::string measurement_frame;       ///< required frame_id of measurements ("" = any)
  std::string leader_broadcast_frame;  ///< required frame_id of leader broadcasts ("" = any)
  std::string odom_frame;              ///< required frame_id of the own odometry ("" = any)
  std::string follower_frame;  ///< frame of the command, status and markers (default: the name)
  double marker_rate = 10.0;   ///< Hz
  int formation_index = 1;     ///< i: which follower of the scenario's formation this is
  /// ~trigger: "timer" (default) or "measurement"; see FollowerNode.
  ControlTrigger trigger = ControlTrigger::kTimer;
  /// ~control_loop: "timer" (default) or "thread" (wall time only); see FollowerNode.
  ControlLoop control_loop = ControlLoop::kTimer;
  /// ~control_priority: SCHED_FIFO priority of the control thread, 1 to 99; 0 (default) leaves
  /// the scheduler alone. Only with control_loop "thread".
  int control_priority = 0;
  /// ~lock_memory: mlockall(MCL_CURRENT | MCL_FUTURE) at start (default false).
  bool lock_memory = false;
};

/// ROS wrapper of RuntimeFollowerController: translates messages and time, nothing else.
///
/// The follower is member ~formation_index of the scenario's formation (layoutFormation()): it
/// keeps the separation d_i of its slot to its target (the leader, or the follower ahead of it in
/// a chain). Subscribes `relative_measurement` (RelativeMeasurement, x_target - x_i) and
/// `leader_broadcast` (LeaderBroadcast of the target: monitored always, its acceleration u_1, plus
/// pinv(B) u_d with controller.leader_information.disturbance, used with ~use_leader_broadcast)
/// and, with a time headway (controller.spacing.time_headway > 0), `odom` (nav_msgs/Odometry:
/// its own state x_i, from which the headway term K_h x_i of (S1) acts).
/// At each control step (see ~trigger below) it picks the mode from the inputs' ages
/// (selectFollowerMode()): with a fresh measurement it runs the controller on
/// y = C (x_target - x_i - d_i), with a stale one the braking fallback; then it publishes
/// `command` (geometry_msgs/AccelStamped), `broadcast` (LeaderBroadcast with that command as
/// input and no state, for a follower behind it), `status` (FollowerStatus), `markers`
/// (visualization_msgs/MarkerArray in the follower's frame, id = formation index) and
/// diagnostics. Messages that are non-finite, of the wrong size, in the wrong frame, stamped 0,
/// in the future, stale on arrival, or not after the last accepted one are refused and counted
/// (InputGuard), and so is a message whose judging throws: no input ends the node. When ROS time
/// goes back (ClockWatch), the inputs of the old timeline are forgotten and the follower brakes
/// until fresh measurements arrive. A tick that runs more than half ~measurement_timeout late
/// (the process itself was stalled) is skipped, and so are the ticks after it until a
/// measurement arrives or half ~measurement_timeout has passed (all counted as missed): the
/// input sent while the process stood still decides the next step, not its absence.
/// dynamic_reconfigure changes the tracker switch, alpha, epsilon and the tracker gain (frequency
/// 0: the scenario file's gain); a set the controller design refuses, or with a non-finite value,
/// is rejected and the old one kept.
///
/// ~trigger decides what runs a control step. "timer" (default): a timer every 1 / control_rate s
/// (ROS time), on the latest accepted measurement; the step is stamped with the timer's time, so
/// a measurement waits up to one period. "measurement": every accepted measurement runs one step
/// at once, inside its callback, stamped with the measurement's header.stamp (the command then
/// carries the stamp of the measurement it answers). The timer still runs at control_rate, but
/// steps only once the measurement is stale (the braking fallback); otherwise it only updates
/// the diagnostics. The estimator integrates one period per step either way, so measurements are
/// expected at control_rate.
///
/// Period accounting (status and diagnostics): ticks (steps run), missed_periods ("timer":
/// periods the timer skipped, its expected times more than 1.5 periods apart counting
/// round(gap / T) - 1; "measurement": the same on the stamps of consecutive accepted
/// measurements), late_periods (steps that started more than T / 2 after they were due: the
/// timer's expected time, or the measurement's stamp) and tick_delay (start - due time).
///
/// ~control_loop decides what runs the fixed-rate tick. "timer" (default): a ros::Timer on a
/// callback queue served by a spinner thread of its own (ROS time; simulated time works).
/// "thread": a PeriodicThread (RealtimeLoop.hpp) that sleeps with clock_nanosleep to absolute
/// CLOCK_MONOTONIC deadlines k / control_rate from its start and runs the same tick at each,
/// stamped with ros::Time::now(); refused under /use_sim_time. Its missed periods ("timer"
/// trigger) are the deadlines it skipped because a tick overran or woke late (it re-aligns to the
/// next deadline ahead), its delay the wake-up time minus the deadline. ~control_priority (1 to
/// 99) runs that thread under SCHED_FIFO, ~lock_memory locks the process's memory
/// (mlockall); the node exits, naming the parameter, if the kernel refuses either.
class FollowerNode {
 public:
  /// @throws ParameterError naming the parameter when the scenario or an option is invalid
  FollowerNode(ros::NodeHandle nh, ros::NodeHandle private_nh);
  ~FollowerNode();
  FollowerNode(const FollowerNode&) = delete;
  FollowerNode& operator=(const FollowerNode&) = delete;

 private:
  void onMeasurement(const RelativeMeasurement::ConstPtr& msg);
  void onLeaderBroadcast(const LeaderBroadcast::ConstPtr& msg);
  void onOdometry(const nav_msgs::Odometry::ConstPtr& msg);
  /// The timer's tick ("timer" loop).
  void onControlTick(const ros::TimerEvent& event);
  /// The control thread's tick ("thread" loop).
  void onLoopTick(const PeriodicTick& tick);
  /// The tick of either loop (mutex_ held), @p delay s after it was due, @p skipped periods
  /// after the previous one ("timer" trigger: counted as missed; "measurement": the steps run
  /// on the measurements, the tick only brakes once they are stale, else updates diagnostics).
  void controlTick(const ros::Time& now, double delay, std::uint32_t skipped);
  /// The mode the inputs' ages give at @p now; fills @p ages.
  FollowerMode modeAt(const ros::Time& now, FollowerInputAges* ages) const;
  /// One control step stamped @p stamp (mutex_ held), @p delay s after it was due: mode, laws,
  /// command, broadcast, status, markers, diagnostics. The one code path of both triggers.
  void controlStep(const ros::Time& stamp, double delay);
  void onReconfigure(FollowerConfig& config, uint32_t level);
  /// Notes a jump back of ROS time at @p now, then judges @p header with @p guard (mutex_ held).
  bool admitHeader(InputGuard& guard, const std_msgs::Header& header, const ros::Time& now);
  /// ROS time went back to @p now (mutex_ held): forget the inputs of the old timeline.
  void onTimeJump(const ros::Time& now);
  void publishStatus(const ros::Time& now, const Eigen::VectorXd& xi,
                     const FollowerInputAges& ages);
  void publishMarkers(const ros::Time& now, const Eigen::VectorXd& xi);
  void diagnose(diagnostic_updater::DiagnosticStatusWrapper& status);
  FollowerConfig configOf(const ControllerParameters& parameters) const;
  void logModeChange(FollowerMode mode);

  FollowerNode(ros::NodeHandle nh, ros::NodeHandle private_nh, const Scenario& scenario);

  ros::NodeHandle nh_;
  ros::NodeHandle private_nh_;
  NodeOptionReader reader_;  ///< the private options, read once
  FollowerNodeOptions options_;
  FormationMember member_;                ///< this follower's place in the formation
  ControllerParameters file_parameters_;  ///< as the scenario gave them
  ControllerParameters parameters_;       ///< as currently in force (scenario + reconfigure)
  RuntimeFollowerController controller_;
  int axes_;

  std::mutex mutex_;  ///< guards everything below against concurrent callbacks (nodelets)
  Eigen::VectorXd relative_state_;  ///< latest accepted x_1 - x_2
  InputGuard measurement_guard_;
  Eigen::VectorXd leader_input_;  ///< a_1 of the latest accepted leader broadcast
  InputGuard leader_guard_;
  Eigen::VectorXd own_state_;  ///< x_i of the latest accepted own odometry (time headway only)
  InputGuard own_state_guard_;
  bool own_state_fresh_ = false;
  ClockWatch clock_;                     ///< jumps back of ROS time
  bool resuming_ = false;                ///< a stall was seen; waiting for input (see controlTick)
  ros::Time resumed_at_;                 ///< when the stall was seen
  std::uint64_t accepted_at_stall_ = 0;  ///< measurements accepted when the stall was seen
  FollowerMode mode_ = FollowerMode::kWaiting;  ///< of the latest tick
  bool leader_fresh_ = false;                   ///< at the latest tick
  double last_xi_norm_ = 0.0;
  double period_ = 0.0;      ///< 1 / control_rate (s)
  std::uint64_t ticks_ = 0;  ///< control steps run
  std::uint32_t missed_periods_ = 0;
  std::uint32_t late_periods_ = 0;
  double tick_delay_ = 0.0;  ///< s, of the latest step
  ros::Time last_expected_;  ///< the timer's previous expected time ("timer")
  bool have_last_expected_ = false;

  ros::Subscriber measurement_subscriber_;
  ros::Subscriber leader_subscriber_;
  ros::Subscriber odometry_subscriber_;  ///< only with a time headway (S1)
  ros::Publisher command_publisher_;
  ros::Publisher broadcast_publisher_;
  ros::Publisher status_publisher_;
  ros::Publisher marker_publisher_;
  ros::Timer timer_;
  /// The control timer has a queue and a thread of its own, so that a flood of input messages
  /// on the node's other queue cannot delay a tick (beyond the brief hold of mutex_).
  ros::CallbackQueue control_queue_;
  std::unique_ptr<ros::AsyncSpinner> control_spinner_;
  diagnostic_updater::Updater diagnostics_;
  FollowerConfig applied_config_;  ///< the reconfigure values in force
  boost::recursive_mutex reconfigure_mutex_;
  dynamic_reconfigure::Server<FollowerConfig> reconfigure_server_;
  /// The "thread" loop: started last in the constructor, stopped first in the destructor.
  PeriodicThread control_thread_;
};

}  // namespace projection_collision_avoidance
