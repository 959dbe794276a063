#include "projection_collision_avoidance/core/DynamicFollowerController.hpp"

#include <stdexcept>
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
  status_.estimate.setZero(n);
}

template <typename Call>
const DynamicFollowerStatus& DynamicFollowerController::visitStep(const Call& call) {
  std::visit([&](auto& controller) { status_ = call(controller); }, controller_);
  return status_;
}

// Each step converts its arguments to the controller's vector types (fixed-size or bounded: no
// allocation); visitStep() copies the controller's status into the run-time-sized one.
const DynamicFollowerStatus& DynamicFollowerController::step(
    const Eigen::Ref<const Eigen::VectorXd>& y) {
  return visitStep([&](auto& controller) -> const auto& {
    using C = std::decay_t<decltype(controller)>;
    return controller.step(as<typename C::OutputVector>(y));
  });
}

const DynamicFollowerStatus& DynamicFollowerController::step(
    const Eigen::Ref<const Eigen::VectorXd>& y,
    const Eigen::Ref<const Eigen::VectorXd>& leader_input) {
  return visitStep([&](auto& controller) -> const auto& {
    using C = std::decay_t<decltype(controller)>;
    return controller.step(as<typename C::OutputVector>(y),
                           as<typename C::InputVector>(leader_input));
  });
}

const DynamicFollowerStatus& DynamicFollowerController::stepWithOwnState(
    const Eigen::Ref<const Eigen::VectorXd>& y,
    const Eigen::Ref<const Eigen::VectorXd>& own_state) {
  return visitStep([&](auto& controller) -> const auto& {
    using C = std::decay_t<decltype(controller)>;
    return controller.stepWithOwnState(as<typename C::OutputVector>(y),
                                       as<typename C::StateVector>(own_state));
  });
}

const DynamicFollowerStatus& DynamicFollowerController::stepWithOwnState(
    const Eigen::Ref<const Eigen::VectorXd>& y, const Eigen::Ref<const Eigen::VectorXd>& own_state,
    const Eigen::Ref<const Eigen::VectorXd>& leader_input) {
  return visitStep([&](auto& controller) -> const auto& {
    using C = std::decay_t<decltype(controller)>;
    return controller.stepWithOwnState(as<typename C::OutputVector>(y),
                                       as<typename C::StateVector>(own_state),
                                       as<typename C::InputVector>(leader_input));
  });
}

const DynamicFollowerStatus& DynamicFollowerController::stepFallback() {
  return visitStep([&](auto& controller) -> const auto& { return controller.stepFallback(); });
}

const DynamicFollowerStatus& DynamicFollowerController::stepFallback(
    const Eigen::Ref<const Eigen::VectorXd>& leader_input) {
  return visitStep([&](auto& controller) -> const auto& {
    using C = std::decay_t<decltype(controller)>;
    return controller.stepFallback(as<typename C::InputVector>(leader_input));
  });
}

void DynamicFollowerController::setDesign(const ControllerDesign& design) {
  const AgentModel& now = this->design().parameters.model;
  const AgentModel& next = design.parameters.model;
  if (now.stateDimension() != next.stateDimension() ||
      now.inputDimension() != next.inputDimension() ||
      now.outputDimension() != next.outputDimension()) {
    throw std::invalid_argument("DynamicFollowerController::setDesign: model sizes changed");
  }
  const Eigen::VectorXd kept = estimate();
  const Eigen::VectorXd kept_command = previousCommand();
  const bool initialized =
      std::visit([](const auto& controller) { return controller.initialized(); }, controller_);
  Variant replacement = makeController(design);
  std::visit(
      [&](auto& controller) {
        using Controller = std::decay_t<decltype(controller)>;
        const typename Controller::InputVector command = kept_command;
        controller.setPreviousCommand(command);
        if (initialized) {
          const typename Controller::StateVector estimate = kept;
          controller.resetEstimate(estimate);
        }
      },
      replacement);
  controller_ = std::move(replacement);
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
        const Controller& source = std::get<Controller>(other.controller_);
        controller.setPreviousCommand(source.previousCommand());
        if (source.initialized()) {
          controller.resetEstimate(source.estimate());
        }
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
