#pragma once

#include <optional>

#include <Eigen/Core>

#include "projection_collision_avoidance/core/CommandProjection.hpp"
#include "projection_collision_avoidance/core/SafetyFilter.hpp"
#include "projection_collision_avoidance/core/TypeDefs.hpp"

namespace projection_collision_avoidance {

/// What the follower knows at one control tick, the argument of FollowerController::step(); an
/// absent entry is unknown at this tick. Vectors of the controller's own sizes (fixed or
/// bounded: no allocation).
template <typename Dims>
struct StepInputs {
  /// y = C (x_1 - x_2 - d) (m, m/s for a double integrator); absent: the fallback runs.
  std::optional<typename Dims::OutputVector> measurement{};
  /// The target's acceleration a_1 (m/s^2), as shared with the follower; absent: unknown.
  std::optional<typename Dims::InputVector> leader_input{};
  /// The follower's own state x_2 (m, m/s), for the time headway (S1); absent: it does not act.
  std::optional<typename Dims::StateVector> own_state{};
  /// The turning slot's own acceleration u_r (m/s^2), (T3): a known input that the command adds
  /// and the estimator's acting augmentation leaves out; absent: a slot fixed in the world.
  std::optional<typename Dims::InputVector> slot_acceleration{};
  /// Delta t / T: the part of a control period T since the previous step's command, which the
  /// rate limit scales its allowed change by (jerk_limit Delta t; CommandRateLimiter::limit());
  /// 1 (the default): a whole period.
  double period_fraction = 1.0;
  /// Half-spaces g_j^T u >= b_j the command must lie in (the neighbours' barriers, (N3)), most
  /// important first, of the command's size; null or empty: none. Not owned.
  const CommandProjection* command_constraints = nullptr;
  /// The barriers (B2) of this step (controller.safety_filter); when given, the command is
  /// filtered by it (B3) and command_constraints is not used. Not owned.
  const SafetyFilter* safety_filter = nullptr;
};

/// StepInputs of any sizes, the argument of DynamicFollowerController::step(): each entry a
/// vector of the model's size (outputDimension(), inputDimension(), stateDimension()).
struct DynamicStepInputs {
  std::optional<Eigen::Ref<const Eigen::VectorXd>> measurement{};        ///< y (m, m/s)
  std::optional<Eigen::Ref<const Eigen::VectorXd>> leader_input{};       ///< a_1 (m/s^2)
  std::optional<Eigen::Ref<const Eigen::VectorXd>> own_state{};          ///< x_2 (m, m/s)
  std::optional<Eigen::Ref<const Eigen::VectorXd>> slot_acceleration{};  ///< u_r (m/s^2)
  double period_fraction = 1.0;  ///< Delta t / T since the previous step (StepInputs)
  const CommandProjection* command_constraints = nullptr;  ///< (N3), as in StepInputs
  const SafetyFilter* safety_filter = nullptr;             ///< (B3), as in StepInputs
};

}  // namespace projection_collision_avoidance
