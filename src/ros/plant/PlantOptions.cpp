#include "plant/PlantOptions.hpp"

#include <algorithm>
#include <cstddef>
#include <limits>
#include <string>
#include <vector>

#include <ros/names.h>

#include "projection_collision_avoidance/core/ParameterError.hpp"

namespace projection_collision_avoidance {
namespace {

std::string frameParameter(NodeOptionReader& reader, const std::string& key,
                           const std::string& fallback) {
  const std::string frame = reader.frame(key, fallback);
  if (frame.empty()) {
    throw ParameterError("~" + key, "must not be empty");
  }
  return frame;
}

constexpr double kInf = std::numeric_limits<double>::infinity();
/// Most entries of ~wait_for_subscribers.
constexpr std::size_t kMaxWaitedTopics = 1024;
constexpr double kTwoPi = 6.283185307179586476925286766559;

/// The agents' names of @p scenario: "leader", then "follower" or "follower_1" .. "follower_N".
std::vector<std::string> agentNames(const Scenario& scenario) {
  std::vector<std::string> names{"leader"};
  if (!scenario.formation.configured) {
    names.emplace_back("follower");
  }
  for (int i = 1; scenario.formation.configured && i <= scenario.formation.followers; ++i) {
    names.push_back("follower_" + std::to_string(i));
  }
  return names;
}

/// A limit in (0, inf]; absent: none (inf).
double limitParameter(NodeOptionReader& reader, const std::string& key) {
  const double limit = reader.number(key, kInf, 0.0, kInf);
  if (!(limit > 0.0)) {
    throw ParameterError("~" + key, "must be > 0 (leave it out for no limit), got 0");
  }
  return limit;
}

/// ~vehicles/<agent>: its kind and the parameters of that kind (others refused by name).
VehicleOptions readVehicle(NodeOptionReader& reader, const std::string& agent, int axes) {
  const std::string prefix = "vehicles/" + agent;
  VehicleOptions v;
  v.key = "~" + prefix;
  const std::string kind = reader.text(prefix + "/kind", toString(v.kind));
  if (kind == "velocity") {
    v.kind = VehicleKind::kVelocity;
  } else if (kind == "unicycle") {
    v.kind = VehicleKind::kUnicycle;
  } else if (kind != "double_integrator") {
    throw ParameterError(v.key + "/kind",
                         "must be double_integrator, velocity or unicycle, got '" + kind + "'");
  }
  if (v.kind == VehicleKind::kUnicycle && axes < 2) {
    throw ParameterError(v.key + "/kind",
                         "unicycle needs a model of 2 or 3 axes, got " + std::to_string(axes));
  }
  std::vector<std::string> allowed{"kind"};
  if (v.kind != VehicleKind::kDoubleIntegrator) {
    allowed.insert(allowed.end(), {"velocity_lag", "max_speed", "heading", "odom_frame"});
    allowed.emplace_back(v.kind == VehicleKind::kUnicycle ? "max_yaw_rate" : "twist_frame");
  }
  for (const std::string& key : reader.mapKeys(prefix)) {
    if (std::find(allowed.begin(), allowed.end(), key) == allowed.end()) {
      std::string takes;
      for (const std::string& name : allowed) {
        takes += (takes.empty() ? "" : ", ") + name;
      }
      throw ParameterError(v.key + "/" + key,
                           "not a parameter of kind " + kind + ", which takes " + takes);
    }
  }
  if (v.kind == VehicleKind::kDoubleIntegrator) {
    return v;
  }
  v.velocity_lag = reader.number(prefix + "/velocity_lag", 0.0, 0.0, 1000.0);
  v.max_speed = limitParameter(reader, prefix + "/max_speed");
  v.heading = reader.number(prefix + "/heading", 0.0, -kTwoPi, kTwoPi);
  v.odom_frame = reader.frame(prefix + "/odom_frame", "");
  if (v.kind == VehicleKind::kUnicycle) {
    v.max_yaw_rate = limitParameter(reader, prefix + "/max_yaw_rate");
  } else {
    const std::string frame = reader.text(prefix + "/twist_frame", "body");
    if (frame != "body" && frame != "world") {
      throw ParameterError(v.key + "/twist_frame", "must be body or world, got '" + frame + "'");
    }
    v.twist_in_body = frame == "body";
  }
  return v;
}

/// ~vehicles: a map by agent name; each name one of the scenario's agents.
std::map<std::string, VehicleOptions> readVehicles(NodeOptionReader& reader,
                                                   const Scenario& scenario) {
  const std::vector<std::string> names = agentNames(scenario);
  std::map<std::string, VehicleOptions> vehicles;
  for (const std::string& agent : reader.mapKeys("vehicles")) {
    if (std::find(names.begin(), names.end(), agent) == names.end()) {
      throw ParameterError("~vehicles/" + agent,
                           "no such agent: the scenario's are leader and " +
                               (names.size() == 2 ? names[1] : names[1] + " .. " + names.back()));
    }
    vehicles[agent] = readVehicle(reader, agent, scenario.controller.model.double_integrator_axes);
  }
  return vehicles;
}

}  // namespace

const char* toString(VehicleKind kind) {
  switch (kind) {
    case VehicleKind::kVelocity:
      return "velocity";
    case VehicleKind::kUnicycle:
      return "unicycle";
    case VehicleKind::kDoubleIntegrator:
      break;
  }
  return "double_integrator";
}

PlantNodeOptions readPlantOptions(NodeOptionReader& reader, const Scenario& scenario) {
  PlantNodeOptions o;
  o.rate = reader.number("rate", scenario.controller.control_rate, 1.0, 10000.0);
  o.world_frame = frameParameter(reader, "world_frame", o.world_frame);
  o.leader_frame = frameParameter(reader, "leader_frame", o.leader_frame);
  o.follower_frame = frameParameter(reader, "follower_frame", o.follower_frame);
  if (o.leader_frame == o.world_frame || o.follower_frame == o.world_frame) {
    throw ParameterError(o.leader_frame == o.world_frame ? "~leader_frame" : "~follower_frame",
                         "must differ from ~world_frame '" + o.world_frame + "'");
  }
  if (o.follower_frame == o.leader_frame) {
    throw ParameterError("~follower_frame",
                         "must differ from ~leader_frame '" + o.leader_frame + "'");
  }
  o.faults.noise_position = reader.number("measurement_noise_position", 0.0, 0.0, 1000.0);
  o.faults.noise_velocity = reader.number("measurement_noise_velocity", 0.0, 0.0, 1000.0);
  o.faults.dropout = reader.number("measurement_dropout", 0.0, 0.0, 1.0);
  if (o.faults.dropout >= 1.0) {
    throw ParameterError("~measurement_dropout",
                         "must lie in [0, 1), got " + std::to_string(o.faults.dropout));
  }
  o.faults.latency = reader.number("measurement_latency", 0.0, 0.0, 1.0);
  o.faults.outage_start = reader.number("measurement_outage_start", 0.0, 0.0, 1e7);
  o.faults.outage_duration = reader.number("measurement_outage_duration", 0.0, 0.0, 1e7);
  o.faults.seed = reader.integer("noise_seed", 1, 0, std::numeric_limits<int>::max());
  o.command_timeout = reader.number("command_timeout", o.command_timeout, 0.0, 3600.0);
  if (o.command_timeout <= 0.0) {
    throw ParameterError("~command_timeout",
                         "must be > 0, got " + std::to_string(o.command_timeout));
  }
  o.clock_skew = readClockSkewOptions(reader);
  o.publish_clock = reader.boolean("publish_clock", false);
  o.real_time_factor = reader.number("real_time_factor", 1.0, 0.0, 1000.0);
  if (o.real_time_factor <= 0.0) {
    throw ParameterError("~real_time_factor",
                         "must lie in (0, 1000], got " + std::to_string(o.real_time_factor));
  }
  o.duration = reader.number("duration", 0.0, 0.0, 1e7);
  o.wait_for_followers = reader.number("wait_for_followers", 0.0, 0.0, 3600.0);
  o.wait_for_subscribers = reader.textList("wait_for_subscribers", kMaxWaitedTopics);
  for (std::size_t i = 0; i < o.wait_for_subscribers.size(); ++i) {
    std::string why = "empty";
    if (o.wait_for_subscribers[i].empty() ||
        !ros::names::validate(o.wait_for_subscribers[i], why)) {
      throw ParameterError("~wait_for_subscribers[" + std::to_string(i) + "]",
                           "must be a topic name: " + why);
    }
  }
  if (!o.wait_for_subscribers.empty() && !(o.publish_clock && o.wait_for_followers > 0.0)) {
    throw ParameterError("~wait_for_subscribers",
                         "needs ~publish_clock and ~wait_for_followers > 0 (the longest wait, in "
                         "wall s): only a plant that drives simulated time can hold it");
  }
  o.lockstep = reader.boolean("lockstep", false);
  o.lockstep_timeout = reader.number("lockstep_timeout", o.lockstep_timeout, 0.001, 3600.0);
  if (o.lockstep && !o.publish_clock) {
    throw ParameterError("~lockstep",
                         "is true but ~publish_clock is false: only a plant that drives "
                         "simulated time can wait for the commands");
  }
  o.vehicles = readVehicles(reader, scenario);
  for (const auto& [agent, vehicle] : o.vehicles) {
    if (vehicle.odom_frame == o.world_frame) {
      throw ParameterError(vehicle.key + "/odom_frame",
                           "must differ from ~world_frame '" + o.world_frame +
                               "' (leave it unset for odometry in the world frame)");
    }
  }
  return o;
}

}  // namespace projection_collision_avoidance
