#pragma once

#include <functional>
#include <mutex>
#include <string>

#include <ros/ros.h>

#include "projection_collision_avoidance/ros/InputAdmission.hpp"

#include "plant/PlantOptions.hpp"

namespace projection_collision_avoidance {

/// When the plant's ticks t_k = k / rate are due, and their stamps.
///
/// With ~publish_clock the plant owns simulated time (stamps t_k from 0) and ticks on a wall
/// timer at rate * real_time_factor, catching up the ticks a late callback missed (at most 50 ms
/// of wall time of them at once; a longer backlog slows simulated time, and a simulation below
/// 90 % of the factor asked for is reported every 5 s). Otherwise it ticks on ROS time, catching
/// up every tick that is due (at most one second of them per callback); scenario time is ROS
/// time under use_sim_time and the time since the first tick otherwise; when ROS time goes back
/// it waits for it to reach the next tick again.
class PlantClock {
 public:
  /// Runs tick k; false to stop (the duration is reached).
  using Tick = std::function<bool(long k)>;
  /// Stops the plant for the reason given.
  using Stop = std::function<void(const std::string& why)>;
  /// ROS time went back by the amount given (s, negative).
  using Jump = std::function<void(double jump)>;

  /// Starts the timers. Every callback runs under @p mutex.
  PlantClock(ros::NodeHandle nh, std::string node_name, const PlantNodeOptions& options,
             std::mutex* mutex, Tick tick, Stop stop, Jump jump);

  /// The stamp of tick k: origin + k / rate.
  ros::Time stampOf(long k) const;
  /// The plant's time: the stamp of the last tick run, or ROS time before the first.
  ros::Time now() const;
  /// Stops the timers (no tick after this returns to its callback).
  void halt();

 private:
  void onWallTick(const ros::WallTimerEvent& event);
  void onRosTick(const ros::TimerEvent& event);
  void rosTick();
  /// Runs the ticks from next_tick_ through @p due while the plant runs.
  void runThrough(long due);

  std::string name_;
  PlantNodeOptions options_;
  std::mutex* mutex_;
  Tick tick_;
  Stop stop_;
  Jump jump_;
  ClockWatch clock_;
  long next_tick_ = 0;
  long last_tick_ = -1;  ///< tick at the duration; -1 = run forever
  bool started_ = false;
  bool running_ = true;
  ros::Time origin_;           ///< ROS time of scenario time 0
  ros::WallTime wall_origin_;  ///< wall time of tick 0 (publish_clock)
  ros::WallTime rate_check_wall_;
  long rate_check_tick_ = 0;
  ros::WallTimer wall_timer_;
  ros::Timer timer_;
};

}  // namespace projection_collision_avoidance
