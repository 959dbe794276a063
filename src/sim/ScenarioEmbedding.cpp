#include "projection_collision_avoidance/sim/ScenarioEmbedding.hpp"

#include "projection_collision_avoidance/core/ParameterError.hpp"

namespace projection_collision_avoidance {
namespace {

Eigen::MatrixXd kroneckerWithIdentity(const Eigen::MatrixXd& M, Eigen::Index k) {
  Eigen::MatrixXd result = Eigen::MatrixXd::Zero(M.rows() * k, M.cols() * k);
  for (Eigen::Index i = 0; i < M.rows(); ++i) {
    for (Eigen::Index j = 0; j < M.cols(); ++j) {
      result.block(i * k, j * k, k, k) = M(i, j) * Eigen::MatrixXd::Identity(k, k);
    }
  }
  return result;
}

/// [a_0 r; a_1 r; ...]: each entry of a one-axis vector along r.
Eigen::VectorXd alongDirection(const Eigen::VectorXd& v, const Eigen::VectorXd& r) {
  Eigen::VectorXd result(v.size() * r.size());
  for (Eigen::Index i = 0; i < v.size(); ++i) {
    result.segment(i * r.size(), r.size()) = v(i) * r;
  }
  return result;
}

SignalProfile embedSignal(const SignalProfile& signal, const Eigen::VectorXd& r) {
  SignalProfile result = signal;
  for (Pulse& pulse : result.pulses) {
    pulse.vector = alongDirection(pulse.vector, r);
  }
  for (Sinusoid& wave : result.sinusoids) {
    wave.amplitude = alongDirection(wave.amplitude, r);
  }
  return result;
}

}  // namespace

Scenario embedAlongDirection(const Scenario& one_axis, const Eigen::VectorXd& direction) {
  const AgentModel& model = one_axis.controller.model;
  if (model.double_integrator_axes != 1 || !model.C.isIdentity(0.0)) {
    throw ParameterError("model", "embedding needs a one-axis double integrator with C = I");
  }
  const Eigen::Index k = direction.size();
  if (k < 1 || k > 3 || !direction.allFinite() || !(direction.norm() > 0.0)) {
    throw ParameterError("direction", "must be a non-zero finite vector of 1 to 3 entries");
  }
  const Eigen::VectorXd r = direction / direction.norm();

  Scenario result = one_axis;
  ControllerParameters& p = result.controller;
  p.model = makeDoubleIntegrator(static_cast<int>(k));
  // States are ordered [p_0..p_(k-1), v_0..v_(k-1)], i.e. the one-axis [p; v] (x) I_k.
  p.separation = alongDirection(one_axis.controller.separation, r);
  p.baseline_gain = kroneckerWithIdentity(one_axis.controller.baseline_gain, k);
  p.estimator_gain = kroneckerWithIdentity(one_axis.controller.estimator_gain, k);
  p.lyapunov_weight = kroneckerWithIdentity(one_axis.controller.lyapunov_weight, k);
  p.tracker_gain = kroneckerWithIdentity(one_axis.controller.tracker_gain, k);
  p.reference_gain = kroneckerWithIdentity(one_axis.controller.reference_gain, k);
  result.leader_initial_state = alongDirection(one_axis.leader_initial_state, r);
  result.follower_initial_state = alongDirection(one_axis.follower_initial_state, r);
  result.leader_input = embedSignal(one_axis.leader_input, r);
  result.disturbance = embedSignal(one_axis.disturbance, r);
  return result;
}

}  // namespace projection_collision_avoidance
