#include "projection_collision_avoidance/core/ControllerDesign.hpp"

#include <algorithm>
#include <cmath>
#include <complex>
#include <sstream>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/SVD>

#include "projection_collision_avoidance/core/BallConstraint.hpp"
#include "projection_collision_avoidance/core/LinearAlgebra.hpp"
#include "projection_collision_avoidance/core/PaperLaws.hpp"
#include "projection_collision_avoidance/core/ParameterError.hpp"
#include "projection_collision_avoidance/core/PlatoonLaws.hpp"
#include "projection_collision_avoidance/core/ValidationChecks.hpp"

namespace projection_collision_avoidance {
namespace {

constexpr int kMaxEstimatorSubsteps = 1000;
constexpr double kRelativeTolerance = 1e-9;
constexpr double kDefaultFallbackVelocityGain = 1.0;  // 1/s

void requireHurwitz(const std::string& key, const std::string& name, const Eigen::MatrixXd& M) {
  if (!isHurwitz(M)) {
    throw ParameterError(
        key, name + " is not Hurwitz; its eigenvalues are " + formatEigenvalues(eigenvalues(M)));
  }
}

void validateScalars(const ControllerParameters& p) {
  detail::requireFinite("controller.control_rate", p.control_rate);
  if (p.control_rate <= 0.0) {
    throw ParameterError("controller.control_rate", "must be positive (Hz)");
  }
  detail::requireFinite("controller.alpha", p.alpha);
  if (p.alpha < 0.0 || p.alpha >= 1.0) {
    throw ParameterError("controller.alpha", "must lie in [0, 1), got " + std::to_string(p.alpha));
  }
  detail::requireFinite("controller.epsilon", p.epsilon);
  if (p.epsilon <= 0.0) {
    throw ParameterError("controller.epsilon",
                         "must be positive, got " + std::to_string(p.epsilon));
  }
  if (!(p.acceleration_limit > 0.0)) {  // also refuses NaN; infinity means no bound
    throw ParameterError("controller.acceleration_limit", "must be positive (m/s^2) or .inf, got " +
                                                              std::to_string(p.acceleration_limit));
  }
  if (!(p.jerk_limit > 0.0)) {  // also refuses NaN; infinity means no bound
    throw ParameterError("controller.jerk_limit",
                         "must be positive (m/s^3) or .inf, got " + std::to_string(p.jerk_limit));
  }
  if (p.estimator_substeps < 1 || p.estimator_substeps > kMaxEstimatorSubsteps) {
    throw ParameterError("controller.estimator.substeps",
                         "must be between 1 and " + std::to_string(kMaxEstimatorSubsteps) +
                             ", got " + std::to_string(p.estimator_substeps));
  }
}

void validateSeparation(const ControllerParameters& p) {
  const AgentModel& model = p.model;
  detail::requireVector("controller.separation", p.separation, model.stateDimension());
  const double norm = p.separation.norm();
  if (!(norm > 0.0)) {
    throw ParameterError("controller.separation",
                         "must be non-zero: the bound (1 - alpha) ||d|| would be zero");
  }
  const double drift = (model.A * p.separation).norm();
  if (drift > kRelativeTolerance * (1.0 + model.A.norm()) * norm) {
    throw ParameterError("controller.separation",
                         "must lie in ker(A), but ||A d|| = " + std::to_string(drift));
  }
}

void validateLyapunovWeight(const Eigen::MatrixXd& Q) {
  const std::string key = "controller.estimator.lyapunov_weight";
  if ((Q - Q.transpose()).norm() > kRelativeTolerance * (1.0 + Q.norm())) {
    throw ParameterError(key, "must be symmetric");
  }
  const Eigen::VectorXd values = Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(Q).eigenvalues();
  if (!(values.minCoeff() > 0.0)) {
    throw ParameterError(key, "must be positive definite; its smallest eigenvalue is " +
                                  std::to_string(values.minCoeff()));
  }
}

}  // namespace

Eigen::MatrixXd doubleIntegratorGain(const Eigen::VectorXd& natural_frequency,
                                     const Eigen::VectorXd& damping, const std::string& key) {
  const Eigen::Index axes = natural_frequency.size();
  if (axes < 1 || damping.size() != axes) {
    throw ParameterError(key, "natural_frequency and damping need one value per axis");
  }
  if (!natural_frequency.allFinite() || !damping.allFinite() ||
      natural_frequency.minCoeff() <= 0.0 || damping.minCoeff() <= 0.0) {
    throw ParameterError(key, "natural_frequency and damping must be positive and finite");
  }
  Eigen::MatrixXd gain = Eigen::MatrixXd::Zero(axes, 2 * axes);
  for (Eigen::Index i = 0; i < axes; ++i) {
    gain(i, i) = natural_frequency(i) * natural_frequency(i);
    gain(i, axes + i) = 2.0 * damping(i) * natural_frequency(i);
  }
  return gain;
}

Eigen::MatrixXd doubleIntegratorFallbackGain(int axes, double velocity_gain) {
  const std::string key = "controller.fallback.velocity_gain";
  if (!(velocity_gain > 0.0) || !std::isfinite(velocity_gain)) {
    throw ParameterError(key,
                         "must be positive and finite (1/s), got " + std::to_string(velocity_gain));
  }
  Eigen::MatrixXd gain = Eigen::MatrixXd::Zero(axes, 2 * axes);
  gain.rightCols(axes).diagonal().setConstant(velocity_gain);
  return gain;
}

namespace {

/// max |R(h lambda)| over the eigenvalues lambda of F, with R(z) = 1 + z + z^2/2 + z^3/6 + z^4/24
/// the amplification of one classical RK4 step on x' = lambda x.
double rk4Amplification(const Eigen::VectorXcd& eigenvalues_of_f, double h) {
  double largest = 0.0;
  for (Eigen::Index i = 0; i < eigenvalues_of_f.size(); ++i) {
    const std::complex<double> z = h * eigenvalues_of_f(i);
    const std::complex<double> r = 1.0 + z * (1.0 + z * (0.5 + z * (1.0 / 6.0 + z / 24.0)));
    largest = std::max(largest, std::abs(r));
  }
  return largest;
}

/// The estimator's RK4 substeps must be stable for its linear part A_c + L C: |R(h lambda)| <= 1
/// with h = T / substeps. Refused naming controller.estimator.substeps when more substeps would
/// do, controller.control_rate when not even kMaxEstimatorSubsteps would. (Beyond that the bound
/// ||xi_hat|| <= xi_max still holds, by the projection and its safeguard, but the estimate is
/// numerical noise.)
void requireStableEstimatorSteps(const Eigen::MatrixXd& estimator_matrix, double period,
                                 int substeps) {
  const Eigen::VectorXcd lambda = eigenvalues(estimator_matrix);
  const double amplification = rk4Amplification(lambda, period / substeps);
  if (amplification <= 1.0 + kRelativeTolerance) {
    return;
  }
  int needed = substeps + 1;
  while (needed <= kMaxEstimatorSubsteps &&
         rk4Amplification(lambda, period / needed) > 1.0 + kRelativeTolerance) {
    ++needed;
  }
  std::ostringstream why;
  why << "RK4 of the estimator is unstable with h = T / substeps = " << period / substeps
      << " s: |R(h lambda)| = " << amplification
      << " > 1 for an eigenvalue lambda of A_c + L C (eigenvalues " << formatEigenvalues(lambda)
      << "); ";
  if (needed <= kMaxEstimatorSubsteps) {
    why << "use substeps >= " << needed << ", a higher control_rate or a smaller L";
    throw ParameterError("controller.estimator.substeps", why.str());
  }
  // No number of substeps helps: the rate (or L) is what is wrong.
  why << "no substeps up to " << kMaxEstimatorSubsteps
      << " suffice: use a higher control_rate or a smaller L";
  throw ParameterError("controller.control_rate", why.str());
}

}  // namespace

ControllerDesign ControllerDesign::create(const ControllerParameters& parameters) {
  const ControllerParameters& p = parameters;
  validateAgentModel(p.model);
  validateScalars(p);
  validateSeparation(p);
  validatePlatoonParameters(p);

  const Eigen::Index n = p.model.stateDimension();
  const Eigen::Index m = p.model.inputDimension();
  const Eigen::Index q = p.model.outputDimension();
  detail::requireMatrix("controller.baseline.gain", p.baseline_gain, m, q);
  detail::requireMatrix("controller.estimator.gain", p.estimator_gain, n, q);
  detail::requireMatrix("controller.estimator.lyapunov_weight", p.lyapunov_weight, n, n);
  detail::requireMatrix("controller.tracker.gain", p.tracker_gain, m, q);
  detail::requireMatrix("controller.tracker.reference_gain", p.reference_gain, m, q);
  validateLyapunovWeight(p.lyapunov_weight);

  ControllerDesign design;
  design.parameters = p;
  const Eigen::MatrixXd& A = p.model.A;
  const Eigen::MatrixXd& B = p.model.B;
  const Eigen::MatrixXd& C = p.model.C;

  design.closed_loop = A - B * p.baseline_gain * C;
  requireHurwitz("controller.baseline.gain", "A_c = A - B G C", design.closed_loop);
  design.estimator_matrix = design.closed_loop + p.estimator_gain * C;
  requireHurwitz("controller.estimator.gain", "A_c + L C", design.estimator_matrix);
  design.tracking_matrix = design.closed_loop - B * p.tracker_gain * C;
  if (p.tracker_enabled) {
    requireHurwitz("controller.tracker.gain", "A_c - B G_e C", design.tracking_matrix);
  }

  design.gamma = solveContinuousLyapunov(design.estimator_matrix, p.lyapunov_weight,
                                         &design.lyapunov_residual);
  if (!(design.lyapunov_residual < 1e-8)) {
    throw ParameterError("controller.estimator.lyapunov_weight",
                         "the Lyapunov equation for Gamma is ill-conditioned (relative residual " +
                             std::to_string(design.lyapunov_residual) + ")");
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> gamma_eigen(design.gamma);
  const double gamma_min = gamma_eigen.eigenvalues().minCoeff();
  const double gamma_max = gamma_eigen.eigenvalues().maxCoeff();
  if (!(gamma_min > 0.0)) {
    throw ParameterError(
        "controller.estimator.lyapunov_weight",
        "Gamma is not positive definite (smallest eigenvalue " + std::to_string(gamma_min) + ")");
  }
  design.gamma_inverse = gamma_eigen.eigenvectors() *
                         gamma_eigen.eigenvalues().cwiseInverse().asDiagonal() *
                         gamma_eigen.eigenvectors().transpose();
  const double q_min =
      Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(p.lyapunov_weight).eigenvalues().minCoeff();
  design.estimator_decay_rate = q_min / (2.0 * gamma_max);
  design.estimator_overshoot = std::sqrt(gamma_max / gamma_min);

  design.fallback_gain = p.fallback_gain;
  if (design.fallback_gain.size() == 0) {
    design.fallback_gain = p.model.isDoubleIntegrator()
                               ? doubleIntegratorFallbackGain(p.model.double_integrator_axes,
                                                              kDefaultFallbackVelocityGain)
                               : Eigen::MatrixXd::Zero(m, n);
  }
  detail::requireMatrix("controller.fallback.gain", design.fallback_gain, m, n);
  design.fallback_matrix = A - B * design.fallback_gain;
  const double growth = eigenvalues(design.fallback_matrix).real().maxCoeff();
  if (growth > kRelativeTolerance * (1.0 + design.fallback_matrix.norm())) {
    throw ParameterError(
        "controller.fallback.gain",
        "A - B K_f has an eigenvalue in the right half-plane; its eigenvalues are " +
            formatEigenvalues(eigenvalues(design.fallback_matrix)));
  }

  design.period = 1.0 / p.control_rate;
  requireStableEstimatorSteps(design.estimator_matrix, design.period, p.estimator_substeps);

  design.output_pseudoinverse = C.completeOrthogonalDecomposition().pseudoInverse();
  design.input_pseudoinverse = B.completeOrthogonalDecomposition().pseudoInverse();
  if (p.leader_disturbance_shared && !p.leader_input_in_command && !p.leader_input_in_estimator) {
    throw ParameterError("controller.leader_information.disturbance",
                         "shares nothing unless leader_information.command or .estimator is true");
  }
  design.headway_gain = timeHeadwayGain(p);
  design.feedforward_smoothing = feedforwardSmoothing(p);
  const double d_norm = p.separation.norm();
  design.xi_max = hardBound(p.alpha, d_norm);
  design.xi_soft = softBound(design.xi_max, p.epsilon);
  design.perimeter = safetyPerimeter(p.alpha, d_norm);
  return design;
}

Eigen::VectorXd ControllerDesign::leaderAcceleration(const Eigen::VectorXd& leader_input,
                                                     const Eigen::VectorXd& disturbance) const {
  return sharedLeaderAcceleration(parameters.leader_disturbance_shared, leader_input,
                                  input_pseudoinverse, disturbance);
}

}  // namespace projection_collision_avoidance
