#pragma once

#include <variant>

#include <Eigen/Core>

#include "projection_collision_avoidance/core/ControllerDesign.hpp"
#include "projection_collision_avoidance/core/FollowerController.hpp"
#include "projection_collision_avoidance/core/StepInputs.hpp"
#include "projection_collision_avoidance/core/TypeDefs.hpp"

namespace projection_collision_avoidance {

/// A FollowerController whose compile-time dimensions are chosen at run time from the model
/// (visitDimensions()): fixed-size for 1/2/3-axis double integrators, bounded otherwise. A step
/// allocates no memory.
class DynamicFollowerController {
 public:
  /// @param design validated parameters
  explicit DynamicFollowerController(const ControllerDesign& design);

  /// One control period (FollowerController::step()) with what the follower knows at this
  /// tick, each entry of the model's size (std::invalid_argument otherwise): a y with a
  /// non-finite entry is treated as missing (the fallback runs, status.measurement_rejected), and
  /// the command is always finite with ||u_2|| <= acceleration_limit.
  const DynamicFollowerStatus& step(const DynamicStepInputs& inputs);

  /// Takes over the estimate (moved into this design's Omega_1, when @p other has one) and the
  /// previous command (moved into this acceleration limit) of @p other, a controller of the same
  /// model sizes (FollowerController::adoptStateOf()): the one way to carry state to a new
  /// design, for example from dynamic_reconfigure. Allocates nothing.
  /// @throws std::invalid_argument when the sizes differ
  void adoptStateOf(const DynamicFollowerController& other);

  /// Forgets the estimate and the previous command (zero, a vehicle at rest); the next step
  /// initialises the estimate as configured.
  void reset();

  const ControllerDesign& design() const;
  const DynamicFollowerStatus& status() const { return status_; }
  /// The estimate the next step will use (m).
  Eigen::VectorXd estimate() const;
  /// The command of the last step (zero before the first and after reset()), from which the next
  /// may change by at most jerk_limit T (m/s^2 for double integrators).
  Eigen::VectorXd previousCommand() const;
  int stateDimension() const { return design().parameters.model.stateDimension(); }
  int inputDimension() const { return design().parameters.model.inputDimension(); }
  int outputDimension() const { return design().parameters.model.outputDimension(); }

 private:
  using Variant =
      std::variant<FollowerController<DoubleIntegrator1D>, FollowerController<DoubleIntegrator2D>,
                   FollowerController<DoubleIntegrator3D>, FollowerController<GenericDimensions>>;

  static Variant makeController(const ControllerDesign& design);
  /// Runs @p call on the controller in use and copies its status into status_.
  template <typename Call>
  const DynamicFollowerStatus& visitStep(const Call& call);

  Variant controller_;
  DynamicFollowerStatus status_;
};

}  // namespace projection_collision_avoidance
