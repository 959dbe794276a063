#pragma once

#include <cmath>

#include "projection_collision_avoidance/sim/WorldSpec.hpp"

namespace projection_collision_avoidance {

/// A follower's true vehicle (VehicleSpec) applied to its commands, tick after tick: saturation
/// at a_max, a first-order lag tau sampled at the control period h, and the gain g. Allocates
/// nothing per tick.
template <typename InputVector>
class VehicleResponse {
 public:
  /// @param spec a validated vehicle
  /// @param period h (s), > 0
  /// @param size m, the input's entries
  VehicleResponse(const VehicleSpec& spec, double period, Eigen::Index size)
      : spec_(spec),
        blend_(spec.actuator_lag > 0.0 ? -std::expm1(-period / spec.actuator_lag) : 1.0),
        lagged_(InputVector::Zero(size)),
        applied_(InputVector::Zero(size)) {}

  /// The input g z_k the plant is driven with over [t_k, t_{k+1}) for the command u_k.
  const InputVector& apply(const InputVector& command) {
    double scale = 1.0;
    const double norm = command.norm();
    if (norm > spec_.acceleration_limit) {
      scale = spec_.acceleration_limit / norm;
    }
    if (spec_.actuator_lag > 0.0) {
      lagged_ += blend_ * (scale * command - lagged_);
    } else {
      lagged_ = scale * command;
    }
    applied_ = spec_.input_gain * lagged_;
    return applied_;
  }

 private:
  VehicleSpec spec_;
  double blend_;         // 1 - e^{-h / tau}
  InputVector lagged_;   // z_k
  InputVector applied_;  // g z_k
};

}  // namespace projection_collision_avoidance
