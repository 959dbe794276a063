#include "projection_collision_avoidance/sim/MeasurementChannel.hpp"

namespace projection_collision_avoidance {
namespace {
/// A sample is due when its age is within this fraction of a period of the latency.
constexpr double kTickTolerance = 1e-6;
}  // namespace

MeasurementChannels::MeasurementChannels(int followers, int axes, double rate,
                                         const MeasurementFaults& faults)
    : axes_(axes),
      rate_(rate),
      faults_(faults),
      channels_(static_cast<std::size_t>(followers)),
      rng_(static_cast<std::mt19937::result_type>(faults.seed)) {}

OutageChange MeasurementChannels::sample(int i, long k, const Eigen::VectorXd& relative_state) {
  Channel& channel = channels_[static_cast<std::size_t>(i)];
  // Draw every random number every tick, so the noise sequence does not depend on dropouts.
  Eigen::VectorXd noise(2 * axes_);
  for (int j = 0; j < 2 * axes_; ++j) {
    noise(j) = normal_(rng_) * (j < axes_ ? faults_.noise_position : faults_.noise_velocity);
  }
  const bool lost = uniform_(rng_) < faults_.dropout;
  const double t = static_cast<double>(k) / rate_;
  const bool in_outage = faults_.outage_duration > 0.0 && t >= faults_.outage_start &&
                         t < faults_.outage_start + faults_.outage_duration;
  OutageChange change = OutageChange::kNone;
  if (in_outage != channel.in_outage) {
    change = in_outage ? OutageChange::kBegan : OutageChange::kEnded;
  }
  channel.in_outage = in_outage;
  if (in_outage) {
    // Nothing sampled; what was sampled before still arrives after its latency.
  } else if (lost) {
    ++channel.dropped;
  } else {
    channel.pending.push_back(Pending{k, relative_state + noise});
  }
  return change;
}

bool MeasurementChannels::deliver(int i, long k, long* sampled_tick, Eigen::VectorXd* state) {
  Channel& channel = channels_[static_cast<std::size_t>(i)];
  if (channel.pending.empty()) {
    return false;
  }
  const Pending& oldest = channel.pending.front();
  if (static_cast<double>(k - oldest.tick) < faults_.latency * rate_ - kTickTolerance) {
    return false;
  }
  *sampled_tick = oldest.tick;
  *state = oldest.state;
  channel.pending.pop_front();
  return true;
}

}  // namespace projection_collision_avoidance
