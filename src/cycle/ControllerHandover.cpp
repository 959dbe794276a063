#include "projection_collision_avoidance/cycle/ControllerHandover.hpp"

#include <stdexcept>
#include <utility>

namespace projection_collision_avoidance {

ControllerHandover::ControllerHandover(std::unique_ptr<DynamicFollowerController> controller)
    : controller_(std::move(controller)) {
  if (!controller_) {
    throw std::invalid_argument("ControllerHandover: a controller");
  }
}

ControllerHandover::~ControllerHandover() {
  delete offered_.exchange(nullptr);
  delete retired_.exchange(nullptr);
}

std::unique_ptr<DynamicFollowerController> ControllerHandover::offer(
    std::unique_ptr<DynamicFollowerController> controller) {
  if (!controller || controller->stateDimension() != controller_->stateDimension() ||
      controller->inputDimension() != controller_->inputDimension() ||
      controller->outputDimension() != controller_->outputDimension()) {
    throw std::invalid_argument("ControllerHandover::offer: a controller of the same model sizes");
  }
  return std::unique_ptr<DynamicFollowerController>(offered_.exchange(controller.release()));
}

std::unique_ptr<DynamicFollowerController> ControllerHandover::retired() {
  return std::unique_ptr<DynamicFollowerController>(retired_.exchange(nullptr));
}

void ControllerHandover::adopt() {
  if (retired_.load(std::memory_order_acquire) != nullptr) {
    return;  // the previous one is not collected yet: adopt at a later tick
  }
  DynamicFollowerController* next = offered_.exchange(nullptr);
  if (next == nullptr) {
    return;
  }
  next->adoptStateOf(*controller_);
  retired_.store(controller_.release(), std::memory_order_release);
  controller_.reset(next);
}

}  // namespace projection_collision_avoidance
