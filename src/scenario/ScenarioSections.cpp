#include "ScenarioSections.hpp"

#include <cmath>
#include <cstddef>
#include <string>

#include "projection_collision_avoidance/core/ParameterError.hpp"

#include "ConfigurationSections.hpp"

namespace projection_collision_avoidance::detail {
namespace {

VehicleSpec readVehicle(YamlReader& parent, const VehicleSpec& defaults) {
  YamlReader section = parent.map("vehicle");
  VehicleSpec vehicle = defaults;
  readNumbers(section, {{"acceleration_limit", &vehicle.acceleration_limit},
                        {"input_gain", &vehicle.input_gain},
                        {"actuator_lag", &vehicle.actuator_lag}});
  section.finish();
  return vehicle;
}

}  // namespace

std::vector<Pulse> readPulses(YamlReader& parent, const std::string& name, Eigen::Index size) {
  std::vector<Pulse> pulses;
  const std::size_t count = parent.sequenceSize(name);
  for (std::size_t i = 0; i < count; ++i) {
    YamlReader item = parent.item(name, i);
    Pulse pulse;
    pulse.start = item.number("start");
    pulse.end = item.number("end");
    pulse.vector = item.vector("vector");
    item.finish();
    if (!std::isfinite(pulse.start)) {
      throw ParameterError(item.key("start"), "must be finite");
    }
    if (!std::isfinite(pulse.end)) {
      throw ParameterError(item.key("end"), "must be finite");
    }
    if (!(pulse.start < pulse.end)) {
      throw ParameterError(item.key("end"), "must be later than start");
    }
    if (pulse.vector.size() != size) {
      throw ParameterError(item.key("vector"), "must have " + std::to_string(size) +
                                                   " entries, got " +
                                                   std::to_string(pulse.vector.size()));
    }
    if (!pulse.vector.allFinite()) {
      throw ParameterError(item.key("vector"), "has a non-finite entry");
    }
    pulses.push_back(pulse);
  }
  return pulses;
}

std::vector<Sinusoid> readSinusoids(YamlReader& parent, const std::string& name) {
  std::vector<Sinusoid> waves;
  const std::size_t count = parent.sequenceSize(name);
  for (std::size_t i = 0; i < count; ++i) {
    YamlReader item = parent.item(name, i);
    Sinusoid wave;
    wave.amplitude = item.vector("amplitude");
    wave.frequency = item.number("frequency");
    wave.phase = item.has("phase") ? item.number("phase") : 0.0;
    item.finish();
    waves.push_back(wave);
  }
  return waves;
}

WorldSpec readWorld(YamlReader& reader, Eigen::Index state_size) {
  WorldSpec world;
  if (!reader.has("world")) {
    return world;
  }
  YamlReader section = reader.map("world");
  world.configured = true;
  if (section.has("seed")) {
    const int seed = section.integer("seed");
    if (seed < 0) {
      throw ParameterError(section.key("seed"),
                           "must be a whole number >= 0, got " + std::to_string(seed));
    }
    world.seed = static_cast<std::uint64_t>(seed);
  }
  if (section.has("vehicle")) {
    world.vehicle = readVehicle(section, VehicleSpec{});
  }
  if (section.has("followers")) {
    const std::size_t count = section.sequenceSize("followers");
    for (std::size_t i = 0; i < count; ++i) {
      YamlReader item = section.item("followers", i);
      FollowerWorldSpec follower;
      follower.index = item.integer("index");
      if (item.has("disturbance")) {
        follower.disturbance.pulses = readPulses(item, "disturbance", state_size);
      }
      if (item.has("sinusoids")) {
        follower.disturbance.sinusoids = readSinusoids(item, "sinusoids");
      }
      if (item.has("vehicle")) {
        follower.has_vehicle = true;
        follower.vehicle = readVehicle(item, world.vehicle);
      }
      item.finish();
      world.followers.push_back(follower);
    }
  }
  if (section.has("gusts")) {
    YamlReader gusts = section.map("gusts");
    GustSpec& g = world.gusts;
    readNumbers(gusts, {{"rate", &g.rate},
                        {"magnitude", &g.magnitude},
                        {"min_duration", &g.min_duration},
                        {"max_duration", &g.max_duration},
                        {"start", &g.start},
                        {"end", &g.end}});
    gusts.finish();
  }
  if (section.has("measurement_noise")) {
    YamlReader noise = section.map("measurement_noise");
    readNumbers(noise, {{"position", &world.noise_position}, {"velocity", &world.noise_velocity}});
    noise.finish();
  }
  section.finish();
  return world;
}

}  // namespace projection_collision_avoidance::detail
