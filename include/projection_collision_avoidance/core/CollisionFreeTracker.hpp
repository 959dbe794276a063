#pragma once

#include "projection_collision_avoidance/core/ControllerDesign.hpp"
#include "projection_collision_avoidance/core/PaperLaws.hpp"
#include "projection_collision_avoidance/core/TypeDefs.hpp"

namespace projection_collision_avoidance {

/// The CF tracker (19): u_a = G_e (y - y_hat) + S_21 y_hat, which pulls the relative error xi
/// toward the collision-free estimate xi_hat (Theorem 3.2); zero when disabled.
template <typename Dims>
class CollisionFreeTracker {
 public:
  using InputVector = typename Dims::InputVector;
  using OutputVector = typename Dims::OutputVector;
  using FeedbackGainMatrix = typename Dims::FeedbackGainMatrix;

  /// @param design validated parameters whose sizes match Dims
  explicit CollisionFreeTracker(const ControllerDesign& design)
      : enabled_(design.parameters.tracker_enabled),
        tracking_gain_(design.parameters.tracker_gain),
        reference_gain_(design.parameters.reference_gain) {}

  /// u_a (19), trackerCommand(), for the measurement y = C xi and the estimate's output
  /// y_hat = C xi_hat; zero when disabled.
  InputVector command(const OutputVector& y, const OutputVector& estimated_output) const {
    if (!enabled_) {
      return InputVector::Zero(tracking_gain_.rows());
    }
    return trackerCommand<Dims>(tracking_gain_, reference_gain_, y, estimated_output);
  }

  bool enabled() const { return enabled_; }

 private:
  bool enabled_;
  FeedbackGainMatrix tracking_gain_;   // G_e
  FeedbackGainMatrix reference_gain_;  // S_21
};

}  // namespace projection_collision_avoidance
