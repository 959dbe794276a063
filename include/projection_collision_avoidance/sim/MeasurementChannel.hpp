#pragma once

#include <deque>
#include <random>
#include <vector>

#include <Eigen/Core>

namespace projection_collision_avoidance {

/// The faults of the simulated relative-measurement channel (the plant's ~measurement_* options).
struct MeasurementFaults {
  double noise_position = 0.0;   ///< m, standard deviation of the measured relative position
  double noise_velocity = 0.0;   ///< m/s, standard deviation of the measured relative velocity
  double dropout = 0.0;          ///< probability that a sample is lost, [0, 1)
  double latency = 0.0;          ///< s from sampling to delivery
  double outage_start = 0.0;     ///< s of simulated time at which an outage begins
  double outage_duration = 0.0;  ///< s without samples; 0: no outage
  int seed = 1;                  ///< seed of the noise and dropout draws
};

/// What a sample did to the outage state of a follower's channel (for the log).
enum class OutageChange { kNone, kBegan, kEnded };

/// The simulated relative-measurement channels of N followers, without ROS: at each tick every
/// channel is sampled (noise added, lost with the dropout probability, nothing in the outage) and
/// delivers, in order, the samples at least `latency` old. One random stream serves all channels,
/// drawn in follower order every tick (noise, then the dropout draw), so that the noise sequence
/// does not depend on which samples are lost.
class MeasurementChannels {
 public:
  /// @param rate ticks per second of simulated time (Hz)
  MeasurementChannels(int followers, int axes, double rate, const MeasurementFaults& faults);

  /// Samples follower @p i's channel at tick @p k (time k / rate) with the true relative state
  /// x_target - x_i (2 axes entries).
  OutageChange sample(int i, long k, const Eigen::VectorXd& relative_state);

  /// The oldest sample of follower @p i that is due at tick @p k (sampled at least `latency`
  /// ago): its tick and measured state. False when none is due.
  bool deliver(int i, long k, long* sampled_tick, Eigen::VectorXd* state);

  /// Samples of follower @p i lost to dropout so far (not the outage).
  unsigned dropped(int i) const { return channels_[static_cast<std::size_t>(i)].dropped; }

 private:
  struct Pending {
    long tick;
    Eigen::VectorXd state;
  };
  struct Channel {
    std::deque<Pending> pending;  ///< sampled, in time order, not yet delivered
    unsigned dropped = 0;
    bool in_outage = false;
  };

  int axes_;
  double rate_;
  MeasurementFaults faults_;
  std::vector<Channel> channels_;
  std::mt19937 rng_;
  std::normal_distribution<double> normal_{0.0, 1.0};
  std::uniform_real_distribution<double> uniform_{0.0, 1.0};
};

}  // namespace projection_collision_avoidance
