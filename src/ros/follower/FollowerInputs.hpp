#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <mutex>
#include <string>

#include <ros/ros.h>

#include "follower/FollowerOptions.hpp"
#include "projection_collision_avoidance/ControllerDesign.hpp"
#include "projection_collision_avoidance/LeaderBroadcast.h"
#include "projection_collision_avoidance/RelativeMeasurement.h"
#include "projection_collision_avoidance/node/FollowerCycle.hpp"
#include "projection_collision_avoidance/ros/InputAdmission.hpp"
#include "projection_collision_avoidance/ros/InputGuard.hpp"

namespace projection_collision_avoidance {

/// What the inputs have refused so far, for the status and the diagnostics.
struct FollowerInputStats {
  std::uint64_t rejected_measurements = 0;
  std::uint64_t rejected_leader_broadcasts = 0;
  std::string measurement_rejection;  ///< the latest, "" once one was accepted after it
  std::string leader_rejection;
};

/// The follower's inputs: subscribes `relative_measurement` and `leader_broadcast`, judges each
/// message with its InputGuard (doc/boundary.md) on the subscriber's thread, and writes what it
/// accepts into the control cycle's lock-free slots. With ~trigger measurement, each accepted
/// measurement runs the cycle's step at once and hands its output to @p on_step. Nothing a
/// message carries can end the node (admitGuarded()).
class FollowerInputs {
 public:
  using StepSink = std::function<void(const FollowerCycleOutput&)>;

  /// @param design the design at start: its model sizes and leader acceleration (pinv(B) u_d),
  ///        which reconfiguration does not change
  /// @param cycle where accepted inputs go; outlives this object
  FollowerInputs(ros::NodeHandle nh, std::string node_name, const FollowerNodeOptions& options,
                 const ControllerDesign& design, FollowerCycle* cycle, StepSink on_step);

  /// Refusal counts and latest reasons (any thread).
  FollowerInputStats stats() const;

 private:
  void onMeasurement(const RelativeMeasurement::ConstPtr& msg);
  void onLeaderBroadcast(const LeaderBroadcast::ConstPtr& msg);
  /// Notes a jump back of ROS time on this input's side (restarting @p guard's timeline), then
  /// judges @p header at @p now.
  static bool admitHeader(InputGuard& guard, ClockWatch& clock, const std_msgs::Header& header,
                          const ros::Time& now);

  std::string name_;
  FollowerNodeOptions options_;
  ControllerDesign design_;
  int axes_;
  FollowerCycle* cycle_;
  StepSink on_step_;

  // Subscriber threads only (one at a time per input: roscpp serialises a subscription).
  InputGuard measurement_guard_;
  ClockWatch measurement_clock_;
  MeasurementSample measurement_;
  Eigen::VectorXd relative_state_;
  FollowerCycleOutput trigger_output_;
  InputGuard leader_guard_;
  ClockWatch leader_clock_;
  LeaderSample leader_;

  // Read by other threads.
  std::atomic<std::uint64_t> rejected_measurements_{0};
  std::atomic<std::uint64_t> rejected_leader_broadcasts_{0};
  mutable std::mutex reasons_mutex_;
  std::string measurement_rejection_;
  std::string leader_rejection_;

  ros::Subscriber measurement_subscriber_;
  ros::Subscriber leader_subscriber_;
};

}  // namespace projection_collision_avoidance
