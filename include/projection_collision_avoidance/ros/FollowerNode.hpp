#pragma once

#include <memory>

#include <ros/ros.h>

namespace projection_collision_avoidance {

class FollowerCycle;
class FollowerInputs;
class FollowerLoop;
class MeasurementAdapter;
class FollowerOutputs;
class FollowerReconfigure;
class MeasurementTrigger;
struct FollowerConfiguration;

/// ROS wrapper of DynamicFollowerController: translates messages and time, nothing else.
///
/// The follower is member ~formation_index of its formation (FollowerConfiguration::member()): it
/// keeps the separation d_i of its slot to its target (the leader, or the follower ahead of it in
/// a chain). Subscribes `relative_measurement` (RelativeMeasurement, x_target - x_i; with
/// ~input odometry, position or tf a MeasurementAdapter makes it; doc/vehicles.md) and
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
/// (InputTimeline), and so is a message whose judging throws: no input ends the node. When ROS
/// time goes back (TimeJumpWatch), the inputs of the old timeline are forgotten and the follower
/// brakes until fresh measurements arrive. A tick that runs more than half ~measurement_timeout
/// late (the process itself was stalled) is skipped, and so are the ticks after it until a
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
/// expected at control_rate; the steps are paced on their stamps (StepPacer), at most one per
/// period, a measurement sooner being held (held_measurements).
///
/// Period accounting (status and diagnostics): ticks (steps run), missed_periods ("timer":
/// periods the timer skipped, its expected times more than 1.5 periods apart counting
/// round(gap / T) - 1; "measurement": the same on the stamps of consecutive accepted
/// measurements), late_periods (steps that started more than T / 2 after they were due: the
/// timer's expected time, or the measurement's stamp) and tick_delay (start - due time).
///
/// ~control_loop decides what runs the fixed-rate tick. "timer" (default): on simulated time a
/// ros::Timer on a callback queue served by a spinner thread of its own; on wall time the
/// SharedTicker thread of its control rate (no real-time priority), which runs the ticks of every
/// follower of the process at that rate in turn, each publishing on that thread.
/// "thread": a PeriodicThread (rt/PeriodicThread.hpp) that sleeps with clock_nanosleep to absolute
/// CLOCK_MONOTONIC deadlines k / control_rate from its start and runs the same tick at each,
/// stamped with ros::Time::now(); refused under /use_sim_time. Its missed periods ("timer"
/// trigger) are the deadlines it skipped because a tick overran or woke late (it re-aligns to the
/// next deadline ahead), its delay the wake-up time minus the deadline. ~control_priority (1 to
/// 99) runs that thread under SCHED_FIFO, ~lock_memory locks the process's memory
/// (mlockall); the node exits, naming the parameter, if the kernel refuses either.
///
/// The parts, each with one job: FollowerInputs (subscriptions and input guards, writing the
/// accepted inputs into lock-free slots; a MeasurementAdapter with another ~input), FollowerCycle
/// (mode, period accounting, the core's step; no ROS), FollowerLoop (the timer or real-time thread
/// that ticks the cycle), FollowerOutputs (messages, markers, diagnostics, log lines; a thread of
/// its own behind a lock-free queue for the real-time loop) and FollowerReconfigure
/// (dynamic_reconfigure). This class reads the parameters and wires them (doc/layout.md).
class FollowerNode {
 public:
  /// @throws ParameterError naming the parameter when the scenario or an option is invalid
  FollowerNode(ros::NodeHandle nh, ros::NodeHandle private_nh);
  ~FollowerNode();
  FollowerNode(const FollowerNode&) = delete;
  FollowerNode& operator=(const FollowerNode&) = delete;

 private:
  FollowerNode(ros::NodeHandle nh, ros::NodeHandle private_nh,
               const FollowerConfiguration& configuration);
  /// Stops the loop, the outputs' thread, reconfiguration and the inputs, in that order.
  void stop();

  std::unique_ptr<FollowerCycle> cycle_;
  std::unique_ptr<FollowerInputs> inputs_;
  std::unique_ptr<MeasurementAdapter> input_adapter_;  ///< ~input other than relative_measurement
  std::unique_ptr<FollowerOutputs> outputs_;
  std::unique_ptr<MeasurementTrigger> trigger_;  ///< ~trigger measurement: a step per measurement
  std::unique_ptr<FollowerReconfigure> reconfigure_;
  std::unique_ptr<FollowerLoop> loop_;  ///< started last, stopped first
};

}  // namespace projection_collision_avoidance
