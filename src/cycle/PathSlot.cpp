#include "projection_collision_avoidance/cycle/PathSlot.hpp"

#include <cmath>
#include <limits>
#include <stdexcept>

namespace projection_collision_avoidance {

PathSlot::PathSlot(const ConvoyParameters& parameters, double period,
                   const GenericDimensions::StateVector& separation, int axes)
    : reference_(parameters, period, separation.head(axes).norm()),
      axes_(axes),
      target_(GenericDimensions::StateVector::Zero(separation.size())),
      period_(period),
      period_ns_(std::llround(1e9 * period)) {
  if (axes < 1 || axes > 3 || separation.size() != 2 * axes) {
    throw std::invalid_argument("PathSlot: 1 to 3 position axes and d of 2 axes entries");
  }
  direction_.setZero();
  direction_.head(axes) = separation.head(axes).normalized();
}

void PathSlot::step(std::int64_t time_ns, bool known,
                    const GenericDimensions::InputVector& own_position,
                    const GenericDimensions::InputVector& own_velocity,
                    const GenericDimensions::StateVector& relative,
                    GenericDimensions::StateVector* slot,
                    GenericDimensions::InputVector* acceleration) {
  Eigen::Vector3d position = Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
  Eigen::Vector3d velocity = position;
  if (known) {
    target_.head(axes_) = own_position.head(axes_) + relative.head(axes_);
    target_.tail(axes_) = own_velocity.head(axes_) + relative.tail(axes_);
    position.setZero();
    velocity.setZero();
    position.head(axes_) = target_.head(axes_);
    velocity.head(axes_) = target_.tail(axes_);
    if (!started_) {
      reference_.reset(position, velocity, direction_);
      started_ = true;
    }
  }
  // The time since the sample before: T exactly when it is one period (ns rounded), nothing for
  // the same time or an earlier one (a stale input, a new timeline's first step).
  double interval = 0.0;
  if (have_time_ && time_ns > time_ns_) {
    const std::int64_t elapsed = time_ns - time_ns_;
    interval = elapsed == period_ns_ ? period_ : 1e-9 * static_cast<double>(elapsed);
  }
  if (!have_time_ || time_ns > time_ns_) {
    time_ns_ = time_ns;
    have_time_ = true;
  }
  sample_ = reference_.tick(position, velocity, interval);
  convoySlotOffset(target_, axes_, sample_, slot);       // D (C4)
  convoySlotAcceleration(sample_, axes_, acceleration);  // u_r (C4)
}

}  // namespace projection_collision_avoidance
