#pragma once

#include <cstdint>
#include <memory>
#include <string>

#include <ros/callback_queue.h>
#include <ros/ros.h>

#include "projection_collision_avoidance/cycle/FollowerCycle.hpp"
#include "projection_collision_avoidance/ros/InputAdmission.hpp"
#include "projection_collision_avoidance/rt/PeriodicThread.hpp"
#include "projection_collision_avoidance/rt/SharedTicker.hpp"

#include "follower/FollowerOptions.hpp"
#include "follower/FollowerOutputs.hpp"

namespace projection_collision_avoidance {

/// What runs the follower's fixed-rate tick (~control_loop) and its period accounting.
///
/// "timer" on simulated time: a ros::Timer on a callback queue and spinner thread of their own,
/// so that a flood of input messages cannot delay a tick; the tick publishes on that thread.
/// Missed periods (~trigger timer): the timer's expected times more than 1.5 periods apart count
/// round(gap / T) - 1.
///
/// "timer" on wall time: a SharedTicker, the thread (no real-time priority) that every follower
/// of the process at this control rate shares, sleeping to absolute CLOCK_MONOTONIC deadlines
/// k T and running the followers' ticks in turn; each tick publishes on that thread. One wake-up
/// per period for all the followers of a nodelet manager, where a ros::Timer costs two per
/// follower (roscpp's timer thread hands each call to a spinner); a step of the system clock does
/// not move the deadlines. Missed periods: the deadlines the thread skipped.
///
/// "thread": the same PeriodicThread, optionally under SCHED_FIFO (~control_priority), refused
/// on simulated time. Its tick allocates and blocks on nothing (with ~trigger timer): the cycle
/// reads lock-free slots and its output goes through FollowerOutputs::post() to the outputs'
/// thread.
///
/// On either thread the tick is stamped with ros::Time::now(); the threads are named ("follower
/// ticks", or @p thread_name for "thread"), so that ps and /proc/<pid>/task/<tid>/comm tell their
/// CPU time apart.
class FollowerLoop {
 public:
  /// Starts the loop at @p control_rate Hz.
  /// @throws ParameterError naming ~control_priority when the kernel refuses the priority
  /// @param node_name prefix of the log lines
  /// @param thread_name name of the "thread" loop's thread (at most 15 characters kept)
  FollowerLoop(ros::NodeHandle nh, std::string node_name, const std::string& thread_name,
               const FollowerNodeOptions& options, double control_rate, FollowerCycle* cycle,
               FollowerOutputs* outputs);
  /// Stops the loop (the thread within one period, at most 10 ms, and a running tick).
  ~FollowerLoop();
  FollowerLoop(const FollowerLoop&) = delete;
  FollowerLoop& operator=(const FollowerLoop&) = delete;

 private:
  void onTimer(const ros::TimerEvent& event);
  void onThreadTick(const PeriodicTick& tick);

  std::string name_;
  bool count_timer_periods_;  ///< ~trigger timer: the timer's skipped periods are missed
  bool post_outputs_;         ///< "thread": outputs go to the outputs' thread
  FollowerCycle* cycle_;
  FollowerOutputs* outputs_;
  double period_;
  FollowerCycleOutput timer_output_;   ///< the timer thread's
  FollowerCycleOutput thread_output_;  ///< the control thread's
  TimeJumpWatch clock_;                ///< jumps back of ROS time at the timer's ticks
  ros::Time last_expected_;
  bool have_last_expected_ = false;
  ros::CallbackQueue queue_;
  ros::Timer timer_;
  std::unique_ptr<ros::AsyncSpinner> spinner_;
  std::unique_ptr<SharedTicker> shared_;  ///< "timer" on wall time
  PeriodicThread thread_;                 ///< "thread"; started last, stopped first
};

}  // namespace projection_collision_avoidance
