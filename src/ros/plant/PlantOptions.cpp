#include "plant/PlantOptions.hpp"

#include <limits>
#include <string>

#include "projection_collision_avoidance/core/ParameterError.hpp"

namespace projection_collision_avoidance {
namespace {

std::string frameParameter(NodeOptionReader& reader, const std::string& key,
                           const std::string& fallback) {
  const std::string frame = reader.text(key, fallback);
  if (frame.empty()) {
    throw ParameterError("~" + key, "must not be empty");
  }
  return frame;
}

}  // namespace

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
  o.publish_clock = reader.boolean("publish_clock", false);
  o.real_time_factor = reader.number("real_time_factor", 1.0, 0.0, 1000.0);
  if (o.real_time_factor <= 0.0) {
    throw ParameterError("~real_time_factor",
                         "must lie in (0, 1000], got " + std::to_string(o.real_time_factor));
  }
  o.duration = reader.number("duration", 0.0, 0.0, 1e7);
  o.wait_for_followers = reader.number("wait_for_followers", 0.0, 0.0, 3600.0);
  o.lockstep = reader.boolean("lockstep", false);
  o.lockstep_timeout = reader.number("lockstep_timeout", o.lockstep_timeout, 0.001, 3600.0);
  if (o.lockstep && !o.publish_clock) {
    throw ParameterError("~lockstep",
                         "is true but ~publish_clock is false: only a plant that drives "
                         "simulated time can wait for the commands");
  }
  return o;
}

}  // namespace projection_collision_avoidance
