#pragma once

#include <Eigen/Core>

#include "projection_collision_avoidance/sim/Scenario.hpp"

namespace projection_collision_avoidance {

/// Embeds a one-axis double-integrator scenario into k = direction.size() axes along the unit
/// vector r = direction / ||direction||: every gain and weight matrix M becomes M (x) I_k
/// (isotropic, so the closed loop commutes with rotations), every state vector [p; v] becomes
/// [p r; v r] and every input vector u becomes u r. The embedded run has the same norms
/// ||xi||, ||xi_hat|| and the same separation as the original.
/// @throws ParameterError if the scenario is not a one-axis double integrator with C = I or the
///         direction is zero, non-finite or longer than 3 entries
Scenario embedAlongDirection(const Scenario& one_axis, const Eigen::VectorXd& direction);

}  // namespace projection_collision_avoidance
