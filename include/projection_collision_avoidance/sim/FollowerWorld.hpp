#pragma once

/// @file
/// What the scenario's `world` section does to one follower, for a plant that integrates it
/// outside cf_sim (the plant node): its disturbance, its true vehicle and the noise on its
/// measured relative state, each as SampledSimulator applies it; and the relative state of
/// another agent as a follower senses it (formation.neighbours). ROS-free, header only.

#include <cstddef>
#include <optional>

#include <Eigen/Core>

#include "projection_collision_avoidance/core/AgentModel.hpp"
#include "projection_collision_avoidance/sim/SignalProfile.hpp"
#include "projection_collision_avoidance/sim/VehicleResponse.hpp"
#include "projection_collision_avoidance/sim/WorldSpec.hpp"

namespace projection_collision_avoidance {

/// Follower i's part of a WorldSpec: w_i(t) (WorldSpec::disturbanceOf()), its true vehicle when
/// the world is configured and the vehicle is not the model (VehicleResponse), and sigma N(...)
/// added to its measured relative state (measurementNoise()) when the world has noise. Without a
/// configured world it is nothing: no disturbance, the command passes unchanged, no noise.
class FollowerWorld {
 public:
  /// @param world a validated world (WorldSpec::validate()), which must outlive this
  /// @param index i, 1 .. N
  /// @param model the agents' model (n states, m inputs, k position entries)
  /// @param duration the run's duration (s) over which the gusts are drawn, as cf_sim draws them
  /// @param period h (s), > 0: the step at which the commands are applied (the vehicle's lag is
  ///        sampled at it)
  FollowerWorld(const WorldSpec& world, int index, const AgentModel& model, double duration,
                double period)
      : world_(&world),
        index_(index),
        state_size_(static_cast<int>(model.stateDimension())),
        position_size_(model.position_dimension),
        disturbance_(world.disturbanceOf(index, model, duration)),
        noisy_(world.configured && (world.noise_position > 0.0 || world.noise_velocity > 0.0)),
        applied_(Eigen::VectorXd::Zero(model.inputDimension())) {
    const VehicleSpec& vehicle = world.vehicleOf(index);
    if (world.configured && !vehicle.ideal()) {
      vehicle_.emplace(vehicle, period, model.inputDimension());
    }
  }

  /// w_i(t) (n entries per vector): its pulses, sinusoids and gusts; empty without a world.
  const SignalProfile& disturbance() const { return disturbance_; }
  /// Whether the follower has a disturbance (pulses or sinusoids).
  bool disturbed() const { return !disturbance_.pulses.empty() || disturbance_.hasSinusoids(); }
  /// Whether the follower's vehicle differs from the model.
  bool hasVehicle() const { return vehicle_.has_value(); }
  /// Whether noise is added to its measurements.
  bool noisy() const { return noisy_; }

  /// The input the plant is driven with over the step for the command u_k held over it (m/s^2):
  /// g z_k of its true vehicle (call once a step, in step order), or u_k itself.
  const Eigen::VectorXd& apply(const Eigen::VectorXd& command) {
    if (vehicle_) {
      return vehicle_->apply(command);
    }
    applied_ = command;
    return applied_;
  }

  /// Adds the world's noise of tick @p tick to the measured relative state @p relative
  /// (n entries: m, then m/s); nothing without noise.
  void addNoise(long tick, Eigen::VectorXd* relative) const {
    if (!noisy_) {
      return;
    }
    for (int e = 0; e < state_size_; ++e) {
      (*relative)(e) += measurementNoise(*world_, index_, tick, e, state_size_, position_size_);
    }
  }

 private:
  const WorldSpec* world_;  // the scenario's, which outlives this
  int index_;
  int state_size_;
  int position_size_;
  SignalProfile disturbance_;
  bool noisy_;
  std::optional<VehicleResponse<Eigen::VectorXd>> vehicle_;
  Eigen::VectorXd applied_;  // u_k without a vehicle
};

/// Agent j's state relative to agent i's, as follower i senses it: @p position = p_j - p_i (m)
/// and @p velocity = v_j - v_i (m/s), the first @p k entries of each (states [p; v], 2 k
/// entries); and whether agent j is within @p radius (m): ||p_j - p_i|| <= radius, as
/// NeighbourConstraints senses (a non-finite distance is not). Writes into the first k entries
/// of each output, which must hold k; allocates nothing.
template <typename Entries>
bool relativeStateWithin(const Eigen::Ref<const Eigen::VectorXd>& own,
                         const Eigen::Ref<const Eigen::VectorXd>& other, int k, double radius,
                         Entries* position, Entries* velocity) {
  Eigen::Vector3d p = Eigen::Vector3d::Zero();
  for (int e = 0; e < k; ++e) {
    const double dp = other(e) - own(e);
    p(e) = dp;
    (*position)[static_cast<std::size_t>(e)] = dp;
    (*velocity)[static_cast<std::size_t>(e)] = other(k + e) - own(k + e);
  }
  return p.norm() <= radius;
}

}  // namespace projection_collision_avoidance
