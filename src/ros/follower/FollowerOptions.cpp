#include "follower/FollowerOptions.hpp"

#include <string>

#include "projection_collision_avoidance/core/ParameterError.hpp"

namespace projection_collision_avoidance {
namespace {

ControlTrigger triggerOf(const std::string& value) {
  if (value == "timer") {
    return ControlTrigger::kTimer;
  }
  if (value == "measurement") {
    return ControlTrigger::kMeasurement;
  }
  throw ParameterError("~trigger", "must be \"timer\" or \"measurement\", got \"" + value + "\"");
}

/// ~control_loop; "thread" is refused on simulated time (@p sim_time).
ControlLoop controlLoopOf(const std::string& value, bool sim_time) {
  if (value == "timer") {
    return ControlLoop::kTimer;
  }
  if (value == "thread") {
    if (sim_time) {
      throw ParameterError("~control_loop",
                           "\"thread\" sleeps on the monotonic clock and cannot follow simulated "
                           "time (/use_sim_time is true): use \"timer\"");
    }
    return ControlLoop::kThread;
  }
  throw ParameterError("~control_loop", "must be \"timer\" or \"thread\", got \"" + value + "\"");
}

}  // namespace

/// Member ~formation_index of the scenario's formation.
FormationMember memberOf(NodeOptionReader& reader, const Scenario& scenario) {
  const int index = reader.integer("formation_index", 1, 1, FormationSpec::kMaxFollowers);
  if (index > scenario.formation.followers) {
    throw ParameterError("~formation_index",
                         "is " + std::to_string(index) + " but the formation has " +
                             std::to_string(scenario.formation.followers) + " follower(s)");
  }
  const std::vector<FormationMember> members =
      layoutFormation(scenario.formation, scenario.controller.separation,
                      scenario.leader_initial_state, scenario.follower_initial_state);
  return members[static_cast<std::size_t>(index - 1)];
}

FollowerNodeOptions readFollowerOptions(NodeOptionReader& reader, const ControllerParameters& p,
                                        const FormationMember& member, bool sim_time) {
  FollowerNodeOptions options;
  options.formation_index = member.index;
  const double period = 1.0 / p.control_rate;
  options.measurement_timeout =
      reader.number("measurement_timeout", options.measurement_timeout, period, 3600.0);
  options.leader_timeout = reader.number("leader_timeout", options.leader_timeout, period, 3600.0);
  options.max_future_stamp =
      reader.number("max_future_stamp", options.max_future_stamp, 0.0, 3600.0);
  options.use_leader_broadcast = reader.boolean("use_leader_broadcast", false);
  options.measurement_frame = reader.text("measurement_frame", "");
  options.leader_broadcast_frame = reader.text("leader_broadcast_frame", "");
  options.odom_frame = reader.text("odom_frame", "");
  options.follower_frame = reader.text("follower_frame", member.name);
  if (options.follower_frame.empty()) {
    throw ParameterError("~follower_frame", "must not be empty");
  }
  options.marker_rate = reader.number("marker_rate", options.marker_rate, 0.0, p.control_rate);
  options.trigger = triggerOf(reader.text("trigger", toString(options.trigger)));
  options.control_loop =
      controlLoopOf(reader.text("control_loop", toString(options.control_loop)), sim_time);
  options.control_priority =
      reader.integer("control_priority", options.control_priority, 0, kMaxControlPriority);
  if (options.control_priority > 0 && options.control_loop != ControlLoop::kThread) {
    throw ParameterError("~control_priority",
                         "is " + std::to_string(options.control_priority) +
                             " but only the \"thread\" control loop has a priority: set "
                             "~control_loop to \"thread\", or this to 0");
  }
  options.lock_memory = reader.boolean("lock_memory", options.lock_memory);
  return options;
}

const char* toString(ControlTrigger trigger) {
  return trigger == ControlTrigger::kMeasurement ? "measurement" : "timer";
}

const char* toString(ControlLoop loop) { return loop == ControlLoop::kThread ? "thread" : "timer"; }

}  // namespace projection_collision_avoidance
