#pragma once

#include <cstdint>
#include <optional>
#include <string>

#include "projection_collision_avoidance/core/ControllerParameters.hpp"
#include "projection_collision_avoidance/core/FollowerConfiguration.hpp"
#include "projection_collision_avoidance/core/Formation.hpp"
#include "projection_collision_avoidance/cycle/NeighbourSensing.hpp"
#include "projection_collision_avoidance/cycle/StampCorrection.hpp"
#include "projection_collision_avoidance/ros/RosParameters.hpp"
#include "projection_collision_avoidance/vehicle/RelativeStateFromOdometry.hpp"

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

/// How `relative_measurement` and `leader_broadcast` travel (~transport).
enum class Transport : std::uint8_t {
  kTcp,  ///< "tcp": TCPROS with TCP_NODELAY (default)
  kUdp,  ///< "udp": UDPROS (lost datagrams are not resent), TCPROS where the publisher has none
};

/// "tcp" or "udp".
const char* toString(Transport transport);

/// Where the relative measurement comes from (~input).
enum class MeasurementInput : std::uint8_t {
  kRelativeMeasurement,  ///< "relative_measurement": the package's RelativeMeasurement
  kOdometry,             ///< "odometry": the own `odom` and the target's `target_odom`
  kPosition,             ///< "position": the target's relative position only (`target_position`,
                         ///< `target_pose`), the velocity filtered
  kTf,                   ///< "tf": tf2 lookups of the two agents' frames, the velocity filtered
};

/// "relative_measurement", "odometry", "position" or "tf".
const char* toString(MeasurementInput input);

/// The odometry input's options (~odometry/...; doc/vehicles.md). With a time headway and no
/// odometry input only the conventions (twist_frame, pose_frame) and the quaternion tolerance
/// are read: the headway's own odometry honours them too.
struct OdometryInputOptions {
  double max_skew = 0.05;              ///< s; largest |t_target - t_self| aligned
  double quaternion_tolerance = 1e-2;  ///< largest |norm(q) - 1| normalised
  bool twist_in_body_frame = true;     ///< twist in child_frame_id (REP 105), else header frame
  double look_ahead = 0.0;             ///< m; l of the own controlled point (unicycle), 0: origin
  double target_look_ahead = 0.0;      ///< m; the target's
  double tf_timeout = 0.0;             ///< s a tf lookup of another frame may wait
  /// The pose (and a header-frame twist) in header.frame_id, or in ~measurement_frame.
  PoseFrame pose_frame = PoseFrame::kHeader;
};

/// The position and tf inputs' options (~position/... and ~tf/...; doc/vehicles.md).
struct PositionInputOptions {
  double velocity_bandwidth = 20.0;  ///< rad/s; ω of the relative velocity filter
  double max_gap = 0.5;              ///< s; a longer gap between positions restarts the filter
  double min_interval = 0.005;  ///< s; a position closer to the last used is ignored (< max_gap)
  double max_speed = 50.0;      ///< m/s; a faster relative velocity estimate is refused
  double tf_timeout = 0.0;      ///< s a tf lookup of a position's frame may wait
  // ~input tf only:
  std::string self_frame;          ///< the follower's body frame (~tf/self_frame)
  std::string target_frame;        ///< its target's body frame (~tf/target_frame)
  double rate = 0.0;               ///< Hz of the lookups (default: the control rate)
  double max_skew = 0.05;          ///< s; largest |t_target − t_self| of the two transforms
  double look_ahead = 0.0;         ///< m; l of the own controlled point along body x
  double target_look_ahead = 0.0;  ///< m; the target's
};

/// Highest ~control_priority (SCHED_FIFO's highest priority on Linux).
constexpr int kMaxControlPriority = 99;

/// The follower node's own options (besides the scenario), read once from its private namespace.
struct FollowerNodeOptions {
  double measurement_timeout = 0.5;  ///< s; an older measurement puts the follower in fallback
  double leader_timeout = 0.5;       ///< s; an older leader broadcast is not used
  /// s; inputs stamped after now + this are refused. 0.25: two 100 ms bursts of a simulated
  /// /clock and 50 ms of transport (doc/boundary.md, "Stamp tolerances").
  double max_future_stamp = 0.25;
  bool use_leader_broadcast = false;   ///< use u_1 from leader_broadcast (always monitored)
  std::string measurement_frame;       ///< required frame_id of measurements ("" = any)
  std::string leader_broadcast_frame;  ///< required frame_id of leader broadcasts ("" = any)
  std::string odom_frame;              ///< required frame_id of the own odometry ("" = any)
  std::string follower_frame;  ///< frame of the command, status and markers (default: the name)
  double marker_rate = 10.0;   ///< Hz
  /// Hz of `status` (every round(control_rate / status_rate) steps, and at each change of mode);
  /// the control rate by default (every step); 0: none
  double status_rate = 0.0;
  int formation_index = 1;  ///< i: which follower of the scenario's formation this is
  /// The scenario's formation.turning with formation.slots: turning (the slot turns with the
  /// heading of the target's velocity, from the own odometry `odom` and the measurement); empty:
  /// world slots.
  std::optional<SlotHeadingParameters> turning;
  /// The scenario's formation.path with formation.slots: path (a convoy on the target's path, its
  /// state from the own odometry `odom` and the measurement); empty: other slots.
  std::optional<ConvoyParameters> path;
  /// The scenario's formation.neighbours: the follower keeps out of every agent of `neighbours`
  /// (NeighbourArray, (N1)-(N3)); empty: the target alone.
  std::optional<NeighbourCycleSettings> neighbours;
  std::string agent_name;   ///< the follower's own id in those arrays (its formation name)
  std::string target_name;  ///< its target's id there ("leader" or "follower_<j>")
  /// ~trigger: "timer" (default) or "measurement"; see FollowerNode.
  ControlTrigger trigger = ControlTrigger::kTimer;
  /// ~control_loop: "timer" (default) or "thread" (wall time only); see FollowerNode.
  ControlLoop control_loop = ControlLoop::kTimer;
  /// ~control_priority: SCHED_FIFO priority of the control thread, 1 to 99; 0 (default) leaves
  /// the scheduler alone. Only with control_loop "thread".
  int control_priority = 0;
  /// ~input: the relative measurement's source (default: the RelativeMeasurement topic).
  MeasurementInput input = MeasurementInput::kRelativeMeasurement;
  OdometryInputOptions odometry;  ///< ~odometry/...: only with input "odometry"
  PositionInputOptions position;  ///< ~position/..., ~tf/...: only with input "position" or "tf"
  /// ~clock_skew/{policy,window,max_offset}: how the measurements' and broadcasts' stamps are
  /// put on this clock (doc/multi_host.md).
  StampCorrectionOptions clock_skew;
  /// ~transport of relative_measurement and leader_broadcast.
  Transport transport = Transport::kTcp;
  /// ~lock_memory: mlockall(MCL_CURRENT | MCL_FUTURE) at start (default false).
  bool lock_memory = false;
};

/// Member ~formation_index of the configured formation (1 for the pair).
/// @throws ParameterError naming ~formation_index
FormationMember memberOf(NodeOptionReader& reader, const FollowerConfiguration& configuration);

/// The follower node's options from its private namespace, each validated (the message names
/// the key): ranges, ~input (and ~odometry/...), ~trigger, ~control_loop ("thread" refused under
/// simulated time, @p sim_time), ~control_priority only with the thread loop.
FollowerNodeOptions readFollowerOptions(NodeOptionReader& reader, const ControllerParameters& p,
                                        const FormationMember& member, bool sim_time);

}  // namespace projection_collision_avoidance
