#pragma once

#include <variant>

#include <Eigen/Core>

#include "projection_collision_avoidance/core/ControllerDesign.hpp"
#include "projection_collision_avoidance/core/FollowerController.hpp"
#include "projection_collision_avoidance/core/TypeDefs.hpp"

namespace projection_collision_avoidance {

/// A FollowerController whose compile-time dimensions are chosen at run time from the model
/// (visitDimensions()): fixed-size for 1/2/3-axis double integrators, bounded otherwise. A step
/// allocates no memory.
class DynamicFollowerController {
 public:
  /// @param design validated parameters
  explicit DynamicFollowerController(const ControllerDesign& design);

  /// One control period (see FollowerController::step()): a y with a non-finite entry is
  /// treated as missing (the fallback runs, status.measurement_rejected), and the command is
  /// always finite with ||u_2|| <= acceleration_limit.
  /// @param y measurement C xi, outputDimension() entries
  const DynamicFollowerStatus& step(const Eigen::Ref<const Eigen::VectorXd>& y);

  /// One control period with the leader's input u_1 (inputDimension() entries).
  const DynamicFollowerStatus& step(const Eigen::Ref<const Eigen::VectorXd>& y,
                                    const Eigen::Ref<const Eigen::VectorXd>& leader_input);

  /// step(y) with the follower's own state x_2 (stateDimension() entries, m and m/s), from which
  /// the time headway acts: u_2 = G y + u_a + u_ff + K_h x_2 (S1). A non-finite x_2 leaves the
  /// headway out for this tick, as step(y) does.
  const DynamicFollowerStatus& stepWithOwnState(const Eigen::Ref<const Eigen::VectorXd>& y,
                                                const Eigen::Ref<const Eigen::VectorXd>& own_state);

  /// step(y, u_1) with the follower's own state x_2, as stepWithOwnState(y, x_2).
  const DynamicFollowerStatus& stepWithOwnState(
      const Eigen::Ref<const Eigen::VectorXd>& y,
      const Eigen::Ref<const Eigen::VectorXd>& own_state,
      const Eigen::Ref<const Eigen::VectorXd>& leader_input);

  /// One control period without a measurement (see FollowerController::stepFallback()).
  const DynamicFollowerStatus& stepFallback();

  /// The fallback with the leader's input u_1 (inputDimension() entries).
  const DynamicFollowerStatus& stepFallback(const Eigen::Ref<const Eigen::VectorXd>& leader_input);

  /// Replaces the parameters (for example from dynamic_reconfigure) and keeps the estimate,
  /// moved into the new Omega_1, and the previous command, moved into the new acceleration
  /// limit, from which the next command's change is limited. Throws std::invalid_argument if the
  /// model's sizes change.
  void setDesign(const ControllerDesign& design);

  /// Takes over the estimate (moved into this design's Omega_1, when @p other has one) and the
  /// previous command (moved into this acceleration limit) of @p other, a controller of the same
  /// model sizes, as setDesign() keeps its own. Allocates nothing.
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
