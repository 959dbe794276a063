#include "projection_collision_avoidance/sim/VehicleModels.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "projection_collision_avoidance/core/ParameterError.hpp"

namespace projection_collision_avoidance {
namespace {

constexpr double kTwoPi = 6.283185307179586476925286766559;

std::string text(double value) {
  std::ostringstream out;
  out << value;
  return out.str();
}

void requireLag(const std::string& key, double tau) {
  if (!(std::isfinite(tau) && tau >= 0.0)) {
    throw ParameterError(key + "/velocity_lag", "must be finite and >= 0 s, got " + text(tau));
  }
}

void requireLimit(const std::string& key, double limit) {
  if (!(limit > 0.0)) {  // also refuses NaN; +inf is no limit
    throw ParameterError(key, "must be > 0 (infinity: no limit), got " + text(limit));
  }
}

void requireStep(double h) {
  if (!(std::isfinite(h) && h >= 0.0)) {
    throw std::invalid_argument("vehicle step must be finite and >= 0 s");
  }
}

/// The first-order lag over a step h: with x = h / τ, v(h) = v0 e^(−x) + v_cmd (1 − e^(−x)) and
/// ∫_0^h v = τ (v0 (1 − e^(−x)) + v_cmd (x − 1 + e^(−x))); each factor to full relative precision
/// for every x ≥ 0.
struct LagFactors {
  double decay;   ///< e^(−x)
  double growth;  ///< 1 − e^(−x)
  double ramp;    ///< x − 1 + e^(−x)

  explicit LagFactors(double x) : decay(0.0), growth(-std::expm1(-x)), ramp(0.0) {
    decay = 1.0 - growth;
    if (x < 1e-2) {  // the closed form cancels: its series, the first term left out < 1e-17 of it
      double term = 0.5 * x * x;
      for (int k = 3; k <= 8; ++k) {
        ramp += term;
        term *= -x / k;
      }
    } else {
      ramp = x - growth;
    }
  }
};

/// sin(a) / a, 1 at a = 0.
double sinc(double a) { return std::abs(a) < 1e-4 ? 1.0 - a * a / 6.0 : std::sin(a) / a; }

}  // namespace

VelocityLagVehicle::VelocityLagVehicle(int axes, const Eigen::Vector3d& position,
                                       const Eigen::Vector3d& velocity,
                                       const VelocityLagParameters& parameters,
                                       const std::string& key)
    : axes_(axes),
      parameters_(parameters),
      position_(Eigen::Vector3d::Zero()),
      velocity_(Eigen::Vector3d::Zero()) {
  requireLag(key, parameters.velocity_lag);
  requireLimit(key + "/max_speed", parameters.max_speed);
  if (!std::isfinite(parameters.heading)) {
    throw ParameterError(key + "/heading", "must be finite, got " + text(parameters.heading));
  }
  if (axes < 1 || axes > 3) {
    throw std::invalid_argument("VelocityLagVehicle: axes must lie in [1, 3]");
  }
  position_.head(axes) = position.head(axes);
  velocity_.head(axes) = velocity.head(axes);
  if (!position_.allFinite() || !velocity_.allFinite()) {
    throw std::invalid_argument("VelocityLagVehicle: the initial state must be finite");
  }
}

bool VelocityLagVehicle::setCommand(const Eigen::Vector3d& command) {
  Eigen::Vector3d held = Eigen::Vector3d::Zero();
  held.head(axes_) = command.head(axes_);
  if (!held.allFinite()) {
    return false;
  }
  const double speed = held.stableNorm();  // no overflow for huge entries
  limited_ = speed > parameters_.max_speed;
  if (limited_) {
    held *= parameters_.max_speed / speed;
  }
  command_ = held;
  return true;
}

void VelocityLagVehicle::advance(double h) {
  requireStep(h);
  const double tau = parameters_.velocity_lag;
  if (h == 0.0) {
    return;
  }
  if (tau == 0.0) {
    velocity_ = command_;
    position_ += command_ * h;
    return;
  }
  const LagFactors lag(h / tau);
  position_ += (velocity_ * lag.growth + command_ * lag.ramp) * tau;
  velocity_ = velocity_ * lag.decay + command_ * lag.growth;
}

Eigen::Vector3d VelocityLagVehicle::bodyVelocity() const {
  const double c = std::cos(parameters_.heading);
  const double s = std::sin(parameters_.heading);
  return {c * velocity_.x() + s * velocity_.y(), -s * velocity_.x() + c * velocity_.y(),
          velocity_.z()};
}

void advanceArc(double v, double omega, double h, double* x, double* y, double* theta) {
  const double half_turn = 0.5 * omega * h;
  const double chord = v * h * sinc(half_turn);
  const double middle = *theta + half_turn;
  *x += chord * std::cos(middle);
  *y += chord * std::sin(middle);
  *theta += omega * h;
}

UnicycleVehicle::UnicycleVehicle(const UnicycleState& initial, const UnicycleParameters& parameters,
                                 const std::string& key)
    : parameters_(parameters), state_(initial) {
  requireLag(key, parameters.velocity_lag);
  requireLimit(key + "/max_speed", parameters.max_speed);
  requireLimit(key + "/max_yaw_rate", parameters.max_yaw_rate);
  if (!(std::isfinite(initial.x) && std::isfinite(initial.y) && std::isfinite(initial.theta) &&
        std::isfinite(initial.v) && std::isfinite(initial.omega))) {
    throw std::invalid_argument("UnicycleVehicle: the initial state must be finite");
  }
  state_.theta = std::remainder(state_.theta, kTwoPi);
}

bool UnicycleVehicle::setCommand(double v, double omega) {
  if (!std::isfinite(v) || !std::isfinite(omega)) {
    return false;
  }
  speed_limited_ = std::abs(v) > parameters_.max_speed;
  yaw_rate_limited_ = std::abs(omega) > parameters_.max_yaw_rate;
  command_v_ = std::clamp(v, -parameters_.max_speed, parameters_.max_speed);
  command_omega_ = std::clamp(omega, -parameters_.max_yaw_rate, parameters_.max_yaw_rate);
  return true;
}

int UnicycleVehicle::substeps(double h, double tau) {
  if (!(tau > 0.0)) {
    return 1;
  }
  const double wanted = std::ceil(kSubstepsPerLag * (h / tau));  // +inf for a tiny τ
  return static_cast<int>(
      std::clamp(wanted, static_cast<double>(kMinSubsteps), static_cast<double>(kMaxSubsteps)));
}

void UnicycleVehicle::advance(double h) {
  requireStep(h);
  if (h == 0.0) {
    return;
  }
  const double tau = parameters_.velocity_lag;
  const bool settled = state_.v == command_v_ && state_.omega == command_omega_;
  if (tau == 0.0 || settled) {
    state_.v = command_v_;
    state_.omega = command_omega_;
    advanceArc(state_.v, state_.omega, h, &state_.x, &state_.y, &state_.theta);
  } else {
    const int n = substeps(h, tau);
    const double hs = h / n;
    const LagFactors lag(hs / tau);
    const double mean_share = tau / hs;  // ∫ over a substep, times this: the mean
    for (int i = 0; i < n; ++i) {
      // Along the arc of the exact means of v and ω over the substep.
      const double v_mean = (state_.v * lag.growth + command_v_ * lag.ramp) * mean_share;
      const double omega_mean =
          (state_.omega * lag.growth + command_omega_ * lag.ramp) * mean_share;
      advanceArc(v_mean, omega_mean, hs, &state_.x, &state_.y, &state_.theta);
      state_.v = state_.v * lag.decay + command_v_ * lag.growth;
      state_.omega = state_.omega * lag.decay + command_omega_ * lag.growth;
    }
  }
  state_.theta = std::remainder(state_.theta, kTwoPi);
}

Eigen::Vector2d UnicycleVehicle::worldVelocity() const {
  return {state_.v * std::cos(state_.theta), state_.v * std::sin(state_.theta)};
}

}  // namespace projection_collision_avoidance
