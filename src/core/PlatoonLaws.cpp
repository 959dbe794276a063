#include "projection_collision_avoidance/core/PlatoonLaws.hpp"

#include <cmath>
#include <string>

#include "projection_collision_avoidance/core/LinearAlgebra.hpp"
#include "projection_collision_avoidance/core/ParameterError.hpp"

namespace projection_collision_avoidance {
namespace {

constexpr double kMaxTimeHeadway = 100.0;            // s
constexpr double kMaxFeedforwardTimeConstant = 1e3;  // s

/// M = [[0, h I], [0, 0]] (n x n) of (S1) for a double integrator.
Eigen::MatrixXd headwayShift(const ControllerParameters& p) {
  const Eigen::Index k = p.model.position_dimension;
  Eigen::MatrixXd shift = Eigen::MatrixXd::Zero(p.model.stateDimension(), p.model.stateDimension());
  shift.block(0, k, k, k).diagonal().setConstant(p.time_headway);
  return shift;
}

}  // namespace

void validatePlatoonParameters(const ControllerParameters& p) {
  const std::string headway_key = "controller.spacing.time_headway";
  if (!std::isfinite(p.time_headway) || p.time_headway < 0.0 || p.time_headway > kMaxTimeHeadway) {
    throw ParameterError(headway_key,
                         "must lie in [0, 100] s, got " + std::to_string(p.time_headway));
  }
  if (p.time_headway > 0.0 && !p.model.isDoubleIntegrator()) {
    throw ParameterError(headway_key,
                         "needs a double_integrator model (the headway moves the position part "
                         "of the slot by the follower's velocity)");
  }
  const std::string gain_key = "controller.leader_information.feedforward.gain";
  const std::string tau_key = "controller.leader_information.feedforward.time_constant";
  if (!(p.feedforward_gain >= 0.0 && p.feedforward_gain <= 1.0)) {  // also refuses NaN
    throw ParameterError(gain_key, "must lie in [0, 1], got " + std::to_string(p.feedforward_gain));
  }
  if (!std::isfinite(p.feedforward_time_constant) || p.feedforward_time_constant < 0.0 ||
      p.feedforward_time_constant > kMaxFeedforwardTimeConstant) {
    throw ParameterError(
        tau_key, "must lie in [0, 1000] s, got " + std::to_string(p.feedforward_time_constant));
  }
  const bool shaped = p.feedforward_gain != 1.0 || p.feedforward_time_constant > 0.0;
  if (shaped && !p.leader_input_in_command) {
    throw ParameterError("controller.leader_information.feedforward",
                         "shapes nothing unless leader_information.command is true");
  }
}

Eigen::MatrixXd timeHeadwayGain(const ControllerParameters& p) {
  const Eigen::Index n = p.model.stateDimension();
  if (!(p.time_headway > 0.0)) {
    return Eigen::MatrixXd::Zero(p.model.inputDimension(), n);
  }
  const Eigen::MatrixXd shift = headwayShift(p);
  // The follower's own loop, x_2' = (A - B G C (I + M)) x_2 + ..., must stay stable.
  const Eigen::MatrixXd own = p.model.A - p.model.B * p.baseline_gain * p.model.C *
                                              (Eigen::MatrixXd::Identity(n, n) + shift);
  if (!isHurwitz(own)) {
    throw ParameterError("controller.spacing.time_headway",
                         "A - B G C (I + M) is not Hurwitz; its eigenvalues are " +
                             formatEigenvalues(eigenvalues(own)));
  }
  return -p.baseline_gain * p.model.C * shift;
}

double feedforwardSmoothing(const ControllerParameters& p) {
  if (!(p.feedforward_time_constant > 0.0)) {
    return 0.0;
  }
  return std::exp(-1.0 / (p.control_rate * p.feedforward_time_constant));
}

}  // namespace projection_collision_avoidance
