#pragma once

#include <cstdint>
#include <functional>
#include <mutex>
#include <string>
#include <utility>

#include <ros/ros.h>

#include "projection_collision_avoidance/ros/InputAdmission.hpp"
#include "projection_collision_avoidance/rt/PeriodicThread.hpp"

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
/// it waits for it to reach the next tick again. On wall time those ticks run on a thread of its
/// own ("plant tick") sleeping to monotonic deadlines, one wake-up per tick. On wall time a backlog
/// of more than 50 ms (a stall, or more agents than the plant can integrate at ~rate) is dropped
/// and reported (at most every 5 s, each drop within 5 s), the ticks after it stamped from the
/// wall clock: stamps stay within 50 ms of the senders' clocks.
///
/// Holding simulated time (publish_clock only): with ~wait_for_followers it stays at its start
/// until every follower listens and every topic of ~wait_for_subscribers has a subscriber (or
/// that many wall s have passed), and the wall schedule starts then; with ~lockstep tick k + 1
/// waits until the commands answering tick k are in (at most ~lockstep_timeout wall s, then it runs
/// without them, counted and reported), the wall schedule restarting from the wait's end; until
/// every agent with a sender has commanded it runs at most at real time.
class PlantClock {
 public:
  /// What the clock asks of the plant and tells it.
  struct Hooks {
    /// Runs tick k; false to stop (the duration is reached).
    std::function<bool(long k)> tick;
    /// Stops the plant for the reason given.
    std::function<void(const std::string& why)> stop;
    /// ROS time went back by the amount given (s, negative).
    std::function<void(double jump)> jump;
    /// ~wait_for_followers: how many of what simulated time waits for are ready (the followers
    /// listening to their measurements, the topics of ~wait_for_subscribers subscribed), and
    /// how many there are.
    std::function<std::pair<int, int>()> listening;
    /// ~lockstep: whether every agent that has commanded answered tick k.
    std::function<bool(long k)> answered;
    /// ~lockstep: whether every agent with a sender has commanded; until then simulated time
    /// runs at most at real time (the nodes still starting join at the pace they would).
    std::function<bool()> all_commanded;
    /// On wall time (ticksOnThread()): runs on the tick thread before each tick, without the
    /// mutex (the commands received since the tick before). May be empty.
    std::function<void()> before_tick;
  };

  /// Whether the plant ticks on a thread of its own (wall time, not publishing /clock) rather
  /// than on a timer of @p options' node handle.
  static bool ticksOnThread(const PlantNodeOptions& options);

  /// Starts the timers. Every callback runs under @p mutex.
  PlantClock(ros::NodeHandle nh, std::string node_name, const PlantNodeOptions& options,
             std::mutex* mutex, Hooks hooks);

  /// The stamp of tick k: origin + k / rate.
  ros::Time stampOf(long k) const;
  /// The plant's time: the stamp of the last tick run, or ROS time before the first.
  ros::Time now() const;
  /// Stops the timers (no tick after this returns to its callback).
  void halt();
  /// Stops the tick thread (wall time), waiting for a running tick. Not from a tick.
  ~PlantClock();
  PlantClock(const PlantClock&) = delete;
  PlantClock& operator=(const PlantClock&) = delete;

 private:
  void onWallTick(const ros::WallTimerEvent& event);
  void onRosTick(const ros::TimerEvent& event);
  /// Wall time: the tick thread's call.
  void onThreadTick(const PeriodicTick& tick);
  /// @param expected when the timer was due (its TimerEvent's current_expected)
  void rosTick(const ros::Time& expected);
  /// Wall time: the last tick to run at ROS time @p now, given the tick @p due by the origin;
  /// a backlog of more than kMaxCatchUp s is dropped (the origin moved to now) and reported.
  long dropWallBacklog(long due, const ros::Time& now);
  /// Wall time: dropWallBacklog() for the tick due now (nothing before the first tick).
  void dropWallBacklogNow();
  /// Wall time: warns of the backlog dropped since the last warning, at most every 5 s (steady
  /// clock); a drop withheld by that limit is reported once it has passed.
  void reportDrops();
  /// The last tick due at ROS time @p now by the origin.
  long dueAt(const ros::Time& now) const;
  /// Runs the ticks from next_tick_ through @p due while the plant runs (and, in lockstep, the
  /// commands answer), at wall time @p wall_now.
  void runThrough(long due, const ros::WallTime& wall_now);
  /// ~wait_for_followers at wall time @p now: whether simulated time still stays at its start.
  bool waitingForFollowers(const ros::WallTime& now);
  /// ~lockstep: whether tick next_tick_ waits for the commands at wall time @p now.
  bool holdForCommands(const ros::WallTime& now);
  /// publish_clock: ticks per wall second now (~real_time_factor, or at most real time in
  /// lockstep until every agent has commanded); moves the wall schedule at a change, at @p now.
  double wallRate(const ros::WallTime& now);

  std::string name_;
  PlantNodeOptions options_;
  std::mutex* mutex_;
  Hooks hooks_;
  TimeJumpWatch clock_;
  long next_tick_ = 0;
  long last_tick_ = -1;  ///< tick at the duration; -1 = run forever
  bool started_ = false;
  bool running_ = true;
  ros::Time origin_;                    ///< ROS time of scenario time 0
  ros::WallTime wall_origin_;           ///< wall time of tick 0 (publish_clock)
  bool waiting_for_followers_ = false;  ///< holding simulated time (~wait_for_followers)
  bool holding_ = false;                ///< lockstep: a tick waits for commands since hold_start_
  ros::WallTime hold_start_;
  std::uint64_t lockstep_timeouts_ = 0;  ///< ticks that ran without every command
  double dropped_seconds_ = 0.0;         ///< wall time: backlog dropped so far (s)
  double unreported_seconds_ = 0.0;      ///< wall time: dropped since the last report (s)
  ros::SteadyTime last_drop_report_;     ///< zero before the first report
  double factor_ = 0.0;  ///< publish_clock: the real-time factor the schedule runs at
  ros::WallTime rate_check_wall_;
  long rate_check_tick_ = 0;
  ros::WallTimer wall_timer_;
  ros::Timer timer_;
  PeriodicThread thread_;  ///< wall time (no ~publish_clock, no use_sim_time); stopped first
};

}  // namespace projection_collision_avoidance
