#include "projection_collision_avoidance/sim/Scenario.hpp"

#include <cmath>
#include <string>

#include "projection_collision_avoidance/core/ValidationChecks.hpp"

namespace projection_collision_avoidance {
namespace {

constexpr double kMaxLinkValues = 16777216.0;  // 2^24 input entries (128 MiB of doubles)

}  // namespace

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
  formation.validateConvoy(controller);
  formation.validateNeighbours(controller);
  world.validate(model, formation.followers, duration);
  if (link.configured) {
    link.validate(controller.control_rate);
    // A sender keeps D + 1 values in flight (SharedLink): bound the memory of the whole formation.
    const double rate = controller.control_rate;
    if (std::isfinite(rate) && rate > 0.0) {
      const double values = (formation.followers + 1.0) * (link.totalDelayPeriods(rate) + 1.0) *
                            model.inputDimension();
      if (values > kMaxLinkValues) {
        throw ParameterError("controller.leader_information.link." +
                                 std::string(link.latency > 0.0 ? "latency" : "delay_periods"),
                             "holds " + std::to_string(values) +
                                 " values in flight across the formation, over the limit of " +
                                 std::to_string(kMaxLinkValues) + "; use a shorter delay");
      }
    }
    if (!controller.leader_input_in_command && !controller.leader_input_in_estimator) {
      throw ParameterError("controller.leader_information.link",
                           "carries nothing unless leader_information.command or .estimator is "
                           "true");
    }
  }
}

}  // namespace projection_collision_avoidance
