#pragma once

/// @file
/// The output side's command timeout: when the follower stops producing commands, the adapter
/// sends the vehicle stack's own stop (zero velocity, or zero acceleration) instead of leaving
/// the last command in force (as diff_drive_controller's cmd_vel_timeout expects).

namespace projection_collision_avoidance {

/// Why check() decided as it did.
enum class WatchdogState {
  kFresh,         ///< the last command is at most timeout old: forward commands
  kNoCommandYet,  ///< none since construction, reset() or time going back: stop
  kTimedOut,      ///< the last command is older than timeout: stop
  kTimeWentBack,  ///< now is before the last command: stop, and forget that command
  kInvalidTime,   ///< now is not finite: stop
};

/// "fresh", "no_command_yet", "timed_out", "time_went_back", "invalid_time".
const char* toString(WatchdogState state);

/// One decision of the watchdog.
struct WatchdogDecision {
  bool send_stop = true;    ///< publish the stack's stop now (again at every check while true)
  bool stop_began = false;  ///< the first stop since the last command was fresh (log it once)
  WatchdogState state = WatchdogState::kNoCommandYet;
};

/// Stop iff no command came within the last timeout: age = now − t_last, stop ⇔ ¬(0 ≤ age ≤
/// timeout) (times in s). A command exactly timeout old is still fresh. Time going back (a looping
/// bag, a reset simulated clock) forgets the last command: the age is unknown, so the adapter stops
/// until a new command arrives. The stop is repeated at every check, since some stacks (PX4's
/// offboard mode through MAVROS) leave their mode without a steady stream of setpoints.
class OutputWatchdog {
 public:
  /// @param timeout (s), finite and > 0
  /// @throws ParameterError("vehicle.command_timeout")
  explicit OutputWatchdog(double timeout);

  /// Notes a command sent (or received from the follower) at @p time (s).
  /// @return false (nothing noted) if @p time is not finite
  bool commandSent(double time);

  /// Whether to send the stop at @p now (s).
  WatchdogDecision check(double now);

  /// Forgets the last command (as at construction).
  void reset();

  double timeout() const { return timeout_; }

 private:
  double timeout_;
  double last_command_ = 0.0;
  bool have_command_ = false;
  bool stopping_ = false;  // the previous check decided to stop
};

}  // namespace projection_collision_avoidance
