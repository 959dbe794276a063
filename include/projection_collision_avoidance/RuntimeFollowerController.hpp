#pragma once

#include <variant>

#include <Eigen/Core>

#include "projection_collision_avoidance/ControllerDesign.hpp"
#include "projection_collision_avoidance/FollowerController.hpp"
#include "projection_collision_avoidance/TypeDefs.hpp"

namespace projection_collision_avoidance {

/// FollowerControllerStatus with run-time sized vectors, for callers that learn the model's sizes
/// from configuration (the ROS nodes). The vectors are sized once; a step only overwrites them.
struct RuntimeFollowerStatus {
  Eigen::VectorXd command;              ///< u_2
  Eigen::VectorXd baseline_command;     ///< G y (2)
  Eigen::VectorXd tracker_command;      ///< u_a (19)
  Eigen::VectorXd feedforward_command;  ///< u_ff (S2) when shared into the command
  Eigen::VectorXd headway_command;      ///< K_h x_2 (S1); 0 without the time headway
  Eigen::VectorXd fallback_command;     ///< K_f xi_hat in the fallback, else 0
  Eigen::VectorXd estimate;             ///< xi_hat used at this tick (m)
  double estimate_norm = 0.0;           ///< ||xi_hat|| (m)
  double constraint_value = 0.0;        ///< f(xi_hat) (13)
  bool command_saturated = false;       ///< the command was scaled onto acceleration_limit
  bool command_rate_limited = false;    ///< the command's change was limited to jerk_limit T
  bool fallback = false;                ///< this tick ran the fallback (no usable measurement)
  bool projection_active = false;
  double boundary_correction = 0.0;    ///< (m)
  bool measurement_rejected = false;   ///< y had a non-finite entry: treated as missing
  bool leader_input_rejected = false;  ///< u_1 had a non-finite entry: taken as unknown
  bool command_overflow = false;       ///< the laws' command was not finite and was replaced
  bool estimate_held = false;          ///< an estimator substep overflowed and was discarded
};

/// A FollowerController whose compile-time dimensions are chosen at run time from the model
/// (visitDimensions()): fixed-size for 1/2/3-axis double integrators, bounded otherwise. A step
/// allocates no memory.
class RuntimeFollowerController {
 public:
  /// @param design validated parameters
  explicit RuntimeFollowerController(const ControllerDesign& design);

  /// One control period (see FollowerController::step()): a y with a non-finite entry is
  /// treated as missing (the fallback runs, status.measurement_rejected), and the command is
  /// always finite with ||u_2|| <= acceleration_limit.
  /// @param y measurement C xi, outputDimension() entries
  const RuntimeFollowerStatus& step(const Eigen::Ref<const Eigen::VectorXd>& y);

  /// One control period with the leader's input u_1 (inputDimension() entries).
  const RuntimeFollowerStatus& step(const Eigen::Ref<const Eigen::VectorXd>& y,
                                    const Eigen::Ref<const Eigen::VectorXd>& leader_input);

  /// step(y) with the follower's own state x_2 (stateDimension() entries, m and m/s), from which
  /// the time headway acts: u_2 = G y + u_a + u_ff + K_h x_2 (S1). A non-finite x_2 leaves the
  /// headway out for this tick, as step(y) does.
  const RuntimeFollowerStatus& stepWithOwnState(const Eigen::Ref<const Eigen::VectorXd>& y,
                                                const Eigen::Ref<const Eigen::VectorXd>& own_state);

  /// step(y, u_1) with the follower's own state x_2, as stepWithOwnState(y, x_2).
  const RuntimeFollowerStatus& stepWithOwnState(
      const Eigen::Ref<const Eigen::VectorXd>& y,
      const Eigen::Ref<const Eigen::VectorXd>& own_state,
      const Eigen::Ref<const Eigen::VectorXd>& leader_input);

  /// One control period without a measurement (see FollowerController::stepFallback()).
  const RuntimeFollowerStatus& stepFallback();

  /// The fallback with the leader's input u_1 (inputDimension() entries).
  const RuntimeFollowerStatus& stepFallback(const Eigen::Ref<const Eigen::VectorXd>& leader_input);

  /// Replaces the parameters (for example from dynamic_reconfigure) and keeps the estimate,
  /// moved into the new Omega_1, and the previous command, moved into the new acceleration
  /// limit, from which the next command's change is limited. Throws std::invalid_argument if the
  /// model's sizes change.
  void setDesign(const ControllerDesign& design);

  /// Forgets the estimate and the previous command (zero, a vehicle at rest); the next step
  /// initialises the estimate as configured.
  void reset();

  const ControllerDesign& design() const;
  const RuntimeFollowerStatus& status() const { return status_; }
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

  Variant controller_;
  RuntimeFollowerStatus status_;
};

}  // namespace projection_collision_avoidance
