#include "projection_collision_avoidance/core/DynamicFollowerController.hpp"

#include <optional>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <utility>

#include "projection_collision_avoidance/core/DimensionDispatch.hpp"

namespace projection_collision_avoidance {
namespace {

/// @p x as the vector type @p Vector of a controller (fixed-size or bounded).
template <typename Vector>
Vector as(const Eigen::Ref<const Eigen::VectorXd>& x) {
  return Vector(x);
}

/// Refuses an input of another size than the model's (std::invalid_argument naming it).
void checkSize(const std::optional<Eigen::Ref<const Eigen::VectorXd>>& x, int size,
               const char* name) {
  if (x && x->size() != size) {
    throw std::invalid_argument(std::string("DynamicFollowerController::step: ") + name + " has " +
                                std::to_string(x->size()) + " entries, the model " +
                                std::to_string(size));
  }
}

}  // namespace

DynamicFollowerController::Variant DynamicFollowerController::makeController(
    const ControllerDesign& design) {
  return visitDimensions(design.parameters.model, [&design](auto dims) {
    return Variant(std::in_place_type<FollowerController<decltype(dims)>>, design);
  });
}

DynamicFollowerController::DynamicFollowerController(const ControllerDesign& design)
    : controller_(makeController(design)) {
  const Eigen::Index n = design.parameters.model.stateDimension();
  const Eigen::Index m = design.parameters.model.inputDimension();
  status_.command.setZero(m);
  status_.baseline_command.setZero(m);
  status_.tracker_command.setZero(m);
  status_.feedforward_command.setZero(m);
  status_.headway_command.setZero(m);
  status_.fallback_command.setZero(m);
  status_.slot_command.setZero(m);
  status_.estimate.setZero(n);
}

template <typename Call>
const DynamicFollowerStatus& DynamicFollowerController::visitStep(const Call& call) {
  std::visit([&](auto& controller) { status_ = call(controller); }, controller_);
  return status_;
}

// The step converts its inputs to the controller's vector types (fixed-size or bounded: no
// allocation); visitStep() copies the controller's status into the run-time-sized one.
const DynamicFollowerStatus& DynamicFollowerController::step(const DynamicStepInputs& inputs) {
  checkSize(inputs.measurement, outputDimension(), "measurement");
  checkSize(inputs.leader_input, inputDimension(), "leader_input");
  checkSize(inputs.own_state, stateDimension(), "own_state");
  checkSize(inputs.slot_acceleration, inputDimension(), "slot_acceleration");
  return visitStep([&](auto& controller) -> const auto& {
    using C = std::decay_t<decltype(controller)>;
    StepInputs<typename C::Dimensions> converted;
    converted.period_fraction = inputs.period_fraction;
    converted.command_constraints = inputs.command_constraints;
    converted.safety_filter = inputs.safety_filter;
    if (inputs.measurement) {
      converted.measurement = as<typename C::OutputVector>(*inputs.measurement);
    }
    if (inputs.leader_input) {
      converted.leader_input = as<typename C::InputVector>(*inputs.leader_input);
    }
    if (inputs.own_state) {
      converted.own_state = as<typename C::StateVector>(*inputs.own_state);
    }
    if (inputs.slot_acceleration) {
      converted.slot_acceleration = as<typename C::InputVector>(*inputs.slot_acceleration);
    }
    return controller.step(converted);
  });
}

void DynamicFollowerController::adoptStateOf(const DynamicFollowerController& other) {
  if (controller_.index() != other.controller_.index() ||
      stateDimension() != other.stateDimension() || inputDimension() != other.inputDimension() ||
      outputDimension() != other.outputDimension()) {
    throw std::invalid_argument("DynamicFollowerController::adoptStateOf: model sizes differ");
  }
  std::visit(
      [&](auto& controller) {
        using Controller = std::decay_t<decltype(controller)>;
        controller.adoptStateOf(std::get<Controller>(other.controller_));
      },
      controller_);
}

void DynamicFollowerController::reset() {
  std::visit([](auto& controller) { controller.reset(); }, controller_);
}

const ControllerDesign& DynamicFollowerController::design() const {
  return std::visit(
      [](const auto& controller) -> const ControllerDesign& { return controller.design(); },
      controller_);
}

Eigen::VectorXd DynamicFollowerController::estimate() const {
  return std::visit([](const auto& controller) -> Eigen::VectorXd { return controller.estimate(); },
                    controller_);
}

Eigen::VectorXd DynamicFollowerController::previousCommand() const {
  return std::visit(
      [](const auto& controller) -> Eigen::VectorXd { return controller.previousCommand(); },
      controller_);
}

}  // namespace projection_collision_avoidance
