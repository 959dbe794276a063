#pragma once

#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "projection_collision_avoidance/core/AgentModel.hpp"
#include "projection_collision_avoidance/sim/SignalProfile.hpp"

namespace projection_collision_avoidance {

/// The true vehicle of a follower, apart from the model its controller is designed with
/// (world.vehicle, world.followers.i.vehicle). Applied to the command u_k of each tick:
///   s_k = u_k min(1, a_max / ||u_k||)                          (saturation)
///   z_k = s_k                                 (tau = 0)
///   z_k = z_{k-1} + (1 - e^{-h / tau}) (s_k - z_{k-1})      (tau > 0; z_{-1} = 0)
///   the plant is driven by g z_k, held over [t_k, t_{k+1})  (h the control period)
struct VehicleSpec {
  /// a_max (units of the input: m/s^2 for a double integrator); infinity: none
  double acceleration_limit = std::numeric_limits<double>::infinity();
  double input_gain = 1.0;    ///< g, > 0: the vehicle's response to a unit command
  double actuator_lag = 0.0;  ///< tau (s), >= 0: a first-order lag sampled at the control period

  /// Whether the vehicle is the model (no limit, g = 1, tau = 0): its command passes unchanged.
  bool ideal() const {
    return !(acceleration_limit < std::numeric_limits<double>::infinity()) && input_gain == 1.0 &&
           actuator_lag == 0.0;
  }
  /// Throws ParameterError naming @p key.acceleration_limit (> 0), .input_gain (> 0, finite),
  /// .actuator_lag (>= 0, finite).
  void validate(const std::string& key) const;
};

/// What differs for follower i (world.followers): its own disturbance and vehicle.
struct FollowerWorldSpec {
  int index = 1;              ///< i, 1 .. N
  SignalProfile disturbance;  ///< w_i(t) (n entries): pulses and sinusoids, as the leader's u_d
  bool has_vehicle = false;   ///< a vehicle of its own, over world.vehicle
  VehicleSpec vehicle;
};

/// Seeded random gusts on every follower (world.gusts): a Poisson process of rate lambda per
/// follower over [start, end); gust q lasts a duration uniform in [min_duration, max_duration]
/// and pushes with w = B g, g of norm uniform in [0, magnitude] and uniform direction.
struct GustSpec {
  double rate = 0.0;                                     ///< lambda (1/s), >= 0; 0: no gusts
  double magnitude = 0.0;                                ///< largest ||g|| (input units: m/s^2)
  double min_duration = 0.5;                             ///< s, > 0
  double max_duration = 2.0;                             ///< s, >= min_duration
  double start = 0.0;                                    ///< s
  double end = std::numeric_limits<double>::infinity();  ///< s, > start
};

/// A world that can hurt (section `world` of a scenario file; simulation only): disturbances on
/// followers, seeded gusts, followers whose vehicles differ from the model, and seeded noise on
/// each follower's measurement of its target. Without the section the run is as before, bit for
/// bit.
struct WorldSpec {
  bool configured = false;
  std::uint64_t seed = 0;                    ///< world.seed: the gusts' and the noise's draws
  VehicleSpec vehicle;                       ///< world.vehicle: every follower's, unless its own
  std::vector<FollowerWorldSpec> followers;  ///< world.followers
  GustSpec gusts;                            ///< world.gusts
  double noise_position = 0.0;               ///< world.measurement_noise.position: sigma (m)
  double noise_velocity = 0.0;               ///< world.measurement_noise.velocity: sigma (m/s)

  /// Checks every key against the model, the formation's @p followers and the run's @p duration
  /// (s); throws ParameterError naming world.* (an index out of 1 .. followers or given twice, a
  /// disturbance of the wrong size, a vehicle or gust value out of range, more than 1e6 gusts
  /// expected a follower, a negative or non-finite noise).
  void validate(const AgentModel& model, int followers, double duration) const;

  /// Follower i's vehicle: its own, else world.vehicle.
  const VehicleSpec& vehicleOf(int index) const;
  /// Follower i's disturbance w_i(t): its pulses and sinusoids plus its gusts over
  /// [0, duration] (gustPulses()); empty for an unconfigured world.
  SignalProfile disturbanceOf(int index, const AgentModel& model, double duration) const;
};

/// The counter-based draw of the world's random values: U(seed, stream, count) =
/// (splitMix64(splitMix64(seed) ^ (stream << 40 | count)) >> 11) 2^-53, in [0, 1). Streams:
/// 4 i for follower i's gusts, 4 i + 1 for its measurement noise.
double worldUniform(std::uint64_t seed, std::uint64_t stream, std::uint64_t count);

/// Follower @p index's gusts over [max(0, start), min(end, duration)) as pulses (n entries each),
/// drawn in this order from stream 4 i, count c = 0, 1, ...: the gap to the next gust
/// -ln(1 - U) / lambda; its duration min + U (max - min); its strength U magnitude; its
/// direction g / ||g|| for g of m standard normal entries, each sqrt(-2 ln(1 - U_a)) cos(2 pi U_b)
/// (a draw of 0 repeats); the pulse is B g clipped to the window's end.
std::vector<Pulse> gustPulses(const GustSpec& gusts, std::uint64_t seed, int index,
                              const AgentModel& model, double duration);

/// A standard normal draw: sqrt(-2 ln(1 - U(2 c))) cos(2 pi U(2 c + 1)) on @p stream.
double worldNormal(std::uint64_t seed, std::uint64_t stream, std::uint64_t count);

/// The noise on follower @p index's measured relative state at tick @p tick, entry e of n:
/// sigma N(seed, 4 i + 1, tick n + e), sigma = noise_position for the first k (position)
/// entries and noise_velocity for the rest.
double measurementNoise(const WorldSpec& world, int index, long tick, int entry, int state_size,
                        int position_size);

}  // namespace projection_collision_avoidance
