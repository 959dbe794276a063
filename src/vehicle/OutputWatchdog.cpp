#include "projection_collision_avoidance/vehicle/OutputWatchdog.hpp"

#include <cmath>
#include <string>

#include "projection_collision_avoidance/core/ParameterError.hpp"

namespace projection_collision_avoidance {

const char* toString(WatchdogState state) {
  switch (state) {
    case WatchdogState::kFresh:
      return "fresh";
    case WatchdogState::kNoCommandYet:
      return "no_command_yet";
    case WatchdogState::kTimedOut:
      return "timed_out";
    case WatchdogState::kTimeWentBack:
      return "time_went_back";
    case WatchdogState::kInvalidTime:
      return "invalid_time";
  }
  return "unknown";
}

OutputWatchdog::OutputWatchdog(double timeout) : timeout_(timeout) {
  if (!(timeout > 0.0) || !std::isfinite(timeout)) {
    throw ParameterError("vehicle.command_timeout",
                         "must be finite and > 0 s, got " + std::to_string(timeout));
  }
}

bool OutputWatchdog::commandSent(double time) {
  if (!std::isfinite(time)) {
    return false;
  }
  last_command_ = time;
  have_command_ = true;
  return true;
}

WatchdogDecision OutputWatchdog::check(double now) {
  WatchdogDecision decision;
  if (!std::isfinite(now)) {
    decision.state = WatchdogState::kInvalidTime;
  } else if (!have_command_) {
    decision.state = WatchdogState::kNoCommandYet;
  } else if (now < last_command_) {
    decision.state = WatchdogState::kTimeWentBack;
    have_command_ = false;
  } else if (now - last_command_ <= timeout_) {
    decision.state = WatchdogState::kFresh;
  } else {
    decision.state = WatchdogState::kTimedOut;
  }
  decision.send_stop = decision.state != WatchdogState::kFresh;
  decision.stop_began = decision.send_stop && !stopping_;
  stopping_ = decision.send_stop;
  return decision;
}

void OutputWatchdog::reset() {
  have_command_ = false;
  stopping_ = false;
}

}  // namespace projection_collision_avoidance
