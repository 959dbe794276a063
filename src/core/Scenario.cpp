#include "projection_collision_avoidance/Scenario.hpp"

#include "ValidationChecks.hpp"

namespace projection_collision_avoidance {

void Scenario::validate() const {
  const AgentModel& model = controller.model;
  validateAgentModel(model);
  detail::requireVector("leader.initial_state", leader_initial_state, model.stateDimension());
  detail::requireVector("follower.initial_state", follower_initial_state, model.stateDimension());
  leader_input.validate("leader.input", model.inputDimension());
  if (!disturbance.sinusoids.empty()) {
    throw ParameterError("leader.disturbance", "takes pulses only");
  }
  disturbance.validate("leader.disturbance", model.stateDimension());
  detail::requireFinite("simulation.duration", duration);
  if (duration <= 0.0) {
    throw ParameterError("simulation.duration", "must be positive (s)");
  }
  formation.validate(model);
}

}  // namespace projection_collision_avoidance
