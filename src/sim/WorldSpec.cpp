#include "projection_collision_avoidance/sim/WorldSpec.hpp"

#include <algorithm>
#include <cmath>
#include <set>
#include <string>

#include "projection_collision_avoidance/core/ParameterError.hpp"
#include "projection_collision_avoidance/sim/SharedLink.hpp"

namespace projection_collision_avoidance {
namespace {

constexpr double kWorldUnitScale = 1.0 / 9007199254740992.0;  // 2^-53
constexpr unsigned kWorldStreamShift = 40;
constexpr double kWorldTwoPi = 6.283185307179586;
/// At most this many gusts a follower (a rate times a duration beyond it is refused).
constexpr double kWorldMaxGusts = 1e6;

std::string followerKey(std::size_t i) { return "world.followers." + std::to_string(i); }

void requireNonNegative(const std::string& key, double value) {
  if (!std::isfinite(value) || value < 0.0) {
    throw ParameterError(key, "must be finite and >= 0, got " + std::to_string(value));
  }
}

}  // namespace

void VehicleSpec::validate(const std::string& key) const {
  if (!(acceleration_limit > 0.0)) {  // infinity allowed: no limit
    throw ParameterError(key + ".acceleration_limit",
                         "must be > 0, got " + std::to_string(acceleration_limit));
  }
  if (!std::isfinite(input_gain) || !(input_gain > 0.0)) {
    throw ParameterError(key + ".input_gain",
                         "must be finite and > 0, got " + std::to_string(input_gain));
  }
  requireNonNegative(key + ".actuator_lag", actuator_lag);
}

void WorldSpec::validate(const AgentModel& model, int followers, double duration) const {
  if (!configured) {
    return;
  }
  vehicle.validate("world.vehicle");
  std::set<int> seen;
  for (std::size_t i = 0; i < this->followers.size(); ++i) {
    const FollowerWorldSpec& follower = this->followers[i];
    const std::string key = followerKey(i);
    if (follower.index < 1 || follower.index > followers) {
      throw ParameterError(key + ".index", "must lie in 1 .. " + std::to_string(followers) +
                                               " (formation.followers), got " +
                                               std::to_string(follower.index));
    }
    if (!seen.insert(follower.index).second) {
      throw ParameterError(key + ".index",
                           "follower " + std::to_string(follower.index) + " is given twice");
    }
    follower.disturbance.validate(key + ".disturbance", model.stateDimension());
    if (follower.has_vehicle) {
      follower.vehicle.validate(key + ".vehicle");
    }
  }
  requireNonNegative("world.gusts.rate", gusts.rate);
  requireNonNegative("world.gusts.magnitude", gusts.magnitude);
  if (!std::isfinite(gusts.min_duration) || !(gusts.min_duration > 0.0)) {
    throw ParameterError("world.gusts.min_duration",
                         "must be finite and > 0, got " + std::to_string(gusts.min_duration));
  }
  if (!std::isfinite(gusts.max_duration) || gusts.max_duration < gusts.min_duration) {
    throw ParameterError("world.gusts.max_duration", "must be finite and >= min_duration, got " +
                                                         std::to_string(gusts.max_duration));
  }
  if (!std::isfinite(gusts.start)) {
    throw ParameterError("world.gusts.start", "must be finite");
  }
  if (std::isnan(gusts.end) || !(gusts.end > gusts.start)) {
    throw ParameterError("world.gusts.end", "must be later than start");
  }
  const double window = std::min(gusts.end, duration) - std::max(0.0, gusts.start);
  if (gusts.rate * window > kWorldMaxGusts) {
    throw ParameterError("world.gusts.rate", "expects more than 1e6 gusts a follower over the run");
  }
  requireNonNegative("world.measurement_noise.position", noise_position);
  requireNonNegative("world.measurement_noise.velocity", noise_velocity);
}

const VehicleSpec& WorldSpec::vehicleOf(int index) const {
  for (const FollowerWorldSpec& follower : followers) {
    if (follower.index == index && follower.has_vehicle) {
      return follower.vehicle;
    }
  }
  return vehicle;
}

SignalProfile WorldSpec::disturbanceOf(int index, const AgentModel& model, double duration) const {
  SignalProfile profile;
  if (!configured) {
    return profile;
  }
  for (const FollowerWorldSpec& follower : followers) {
    if (follower.index == index) {
      profile = follower.disturbance;
    }
  }
  std::vector<Pulse> gust = gustPulses(gusts, seed, index, model, duration);
  profile.pulses.insert(profile.pulses.end(), gust.begin(), gust.end());
  return profile;
}

double worldUniform(std::uint64_t seed, std::uint64_t stream, std::uint64_t count) {
  const std::uint64_t key = (stream << kWorldStreamShift) | count;
  return static_cast<double>(splitMix64(splitMix64(seed) ^ key) >> 11U) * kWorldUnitScale;
}

double worldNormal(std::uint64_t seed, std::uint64_t stream, std::uint64_t count) {
  const double a = worldUniform(seed, stream, 2 * count);
  const double b = worldUniform(seed, stream, 2 * count + 1);
  return std::sqrt(-2.0 * std::log1p(-a)) * std::cos(kWorldTwoPi * b);
}

std::vector<Pulse> gustPulses(const GustSpec& gusts, std::uint64_t seed, int index,
                              const AgentModel& model, double duration) {
  std::vector<Pulse> pulses;
  const double begin = std::max(0.0, gusts.start);
  const double finish = std::min(gusts.end, duration);
  if (!(gusts.rate > 0.0) || !(gusts.magnitude > 0.0) || !(finish > begin)) {
    return pulses;
  }
  if (gusts.rate * (finish - begin) > kWorldMaxGusts) {
    throw ParameterError("world.gusts.rate", "makes more than 1e6 gusts a follower");
  }
  const std::uint64_t stream = 4U * static_cast<std::uint64_t>(index);
  const Eigen::Index m = model.inputDimension();
  std::uint64_t count = 0;
  auto next = [&]() { return worldUniform(seed, stream, count++); };
  double t = begin;
  while (true) {
    t += -std::log1p(-next()) / gusts.rate;
    const double length = gusts.min_duration + next() * (gusts.max_duration - gusts.min_duration);
    const double strength = next() * gusts.magnitude;
    Eigen::VectorXd direction(m);
    do {
      for (Eigen::Index e = 0; e < m; ++e) {
        const double a = next();
        const double b = next();
        direction(e) = std::sqrt(-2.0 * std::log1p(-a)) * std::cos(kWorldTwoPi * b);
      }
    } while (!(direction.norm() > 0.0));
    if (!(t < finish)) {
      break;
    }
    Pulse pulse;
    pulse.start = t;
    pulse.end = std::min(t + length, finish);
    pulse.vector = model.B * (strength / direction.norm() * direction);
    pulses.push_back(pulse);
  }
  return pulses;
}

double measurementNoise(const WorldSpec& world, int index, long tick, int entry, int state_size,
                        int position_size) {
  const double sigma = entry < position_size ? world.noise_position : world.noise_velocity;
  if (!(sigma > 0.0)) {
    return 0.0;
  }
  const std::uint64_t stream = 4U * static_cast<std::uint64_t>(index) + 1U;
  const auto count = static_cast<std::uint64_t>(tick) * static_cast<std::uint64_t>(state_size) +
                     static_cast<std::uint64_t>(entry);
  return sigma * worldNormal(world.seed, stream, count);
}

}  // namespace projection_collision_avoidance
