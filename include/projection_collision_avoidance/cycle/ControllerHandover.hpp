#pragma once

#include <atomic>
#include <memory>

#include "projection_collision_avoidance/core/DynamicFollowerController.hpp"

namespace projection_collision_avoidance {

/// The controller in force and its replacement by a new design without a lock: another thread
/// offers a controller built for the new design, a tick adopts it (DynamicFollowerController::
/// adoptStateOf(): the estimate and the previous command carry over) and leaves the old one to be
/// collected off the control thread. Adoption allocates and frees nothing.
class ControllerHandover {
 public:
  /// @param controller the controller at start (not null; std::invalid_argument otherwise)
  explicit ControllerHandover(std::unique_ptr<DynamicFollowerController> controller);
  ~ControllerHandover();
  ControllerHandover(const ControllerHandover&) = delete;
  ControllerHandover& operator=(const ControllerHandover&) = delete;

  /// Hands over a controller of the same model sizes (std::invalid_argument otherwise) for a
  /// coming adopt(), once the controller it replaced last time has been collected with retired().
  /// A controller offered before and not yet adopted is returned for disposal.
  std::unique_ptr<DynamicFollowerController> offer(
      std::unique_ptr<DynamicFollowerController> controller);
  /// The controller replaced by the last adoption, for disposal off the control thread.
  std::unique_ptr<DynamicFollowerController> retired();

  /// On the control thread: adopts the offered controller, if any and the one it replaced last
  /// time is collected.
  void adopt();
  /// The controller in force (control thread, or before start).
  DynamicFollowerController& current() { return *controller_; }
  const DynamicFollowerController& current() const { return *controller_; }

 private:
  std::unique_ptr<DynamicFollowerController> controller_;
  std::atomic<DynamicFollowerController*> offered_{nullptr};
  std::atomic<DynamicFollowerController*> retired_{nullptr};
};

}  // namespace projection_collision_avoidance
