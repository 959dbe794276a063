#include "projection_collision_avoidance/sim/SharedLink.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "projection_collision_avoidance/core/ParameterError.hpp"

namespace projection_collision_avoidance {
namespace {

constexpr double kArrivalTolerance = 1e-9;               // periods
constexpr int kReceiverShift = 40;                       // tick < 2^40, receiver < 2^24
constexpr double kUnitScale = 1.0 / 9007199254740992.0;  // 2^-53

const char* const kKey = "controller.leader_information.link";

std::string key(const char* name) { return std::string(kKey) + "." + name; }

}  // namespace

int LinkSpec::totalDelayPeriods(double control_rate) const {
  const double latency_periods = std::ceil(latency * control_rate - kArrivalTolerance);
  return delay_periods + static_cast<int>(std::max(0.0, latency_periods));
}

void LinkSpec::validate(double control_rate) const {
  if (delay_periods < 0 || delay_periods > kMaxDelayPeriods) {
    throw ParameterError(key("delay_periods"), "must lie in [0, " +
                                                   std::to_string(kMaxDelayPeriods) + "], got " +
                                                   std::to_string(delay_periods));
  }
  if (!std::isfinite(latency) || latency < 0.0 || latency > kMaxLatency) {
    throw ParameterError(key("latency"), "must lie in [0, " + std::to_string(kMaxLatency) +
                                             "] s, got " + std::to_string(latency));
  }
  if (!(dropout >= 0.0 && dropout < 1.0)) {  // also refuses NaN
    throw ParameterError(key("dropout"),
                         "must be a probability in [0, 1), got " + std::to_string(dropout));
  }
  if (std::isfinite(control_rate) && control_rate > 0.0) {
    const double periods =
        delay_periods + std::max(0.0, std::ceil(latency * control_rate - kArrivalTolerance));
    if (periods > kMaxDelayPeriods) {
      throw ParameterError(key(latency > 0.0 ? "latency" : "delay_periods"),
                           "makes a delay of " + std::to_string(periods) +
                               " control periods, over the limit of " +
                               std::to_string(kMaxDelayPeriods));
    }
  }
}

std::uint64_t splitMix64(std::uint64_t x) {
  std::uint64_t z = x + 0x9E3779B97F4A7C15ULL;
  z = (z ^ (z >> 30U)) * 0xBF58476D1CE4E5B9ULL;
  z = (z ^ (z >> 27U)) * 0x94D049BB133111EBULL;
  return z ^ (z >> 31U);
}

bool linkMessageLost(std::uint64_t seed, int receiver, long tick, double dropout) {
  if (!(dropout > 0.0)) {
    return false;
  }
  const std::uint64_t key_bits =
      (static_cast<std::uint64_t>(receiver) << kReceiverShift) | static_cast<std::uint64_t>(tick);
  const std::uint64_t bits = splitMix64(splitMix64(seed) ^ key_bits);
  const double uniform = static_cast<double>(bits >> 11U) * kUnitScale;  // [0, 1), 53 bits
  return uniform < dropout;
}

LinkVerdict judgeLinkMessage(const LinkSpec& spec, double control_rate, int receiver,
                             double stamp) {
  LinkVerdict verdict;
  const double tick = std::round(stamp * control_rate);
  constexpr double kLastTick = static_cast<double>(1L << kReceiverShift) - 1.0;
  verdict.tick = tick > 0.0 ? static_cast<long>(std::min(tick, kLastTick)) : 0;  // NaN: 0
  verdict.lost = linkMessageLost(spec.seed, receiver, verdict.tick, spec.dropout);
  verdict.release = stamp + spec.totalDelayPeriods(control_rate) / control_rate;
  return verdict;
}

}  // namespace projection_collision_avoidance
