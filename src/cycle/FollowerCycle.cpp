#include "projection_collision_avoidance/cycle/FollowerCycle.hpp"

#include <cmath>
#include <limits>
#include <stdexcept>
#include <utility>

namespace projection_collision_avoidance {
namespace {

constexpr double kNanosecond = 1e-9;

/// Adds without wrapping around.
void addSaturated(std::uint32_t* counter, std::uint32_t amount) {
  *counter = *counter > std::numeric_limits<std::uint32_t>::max() - amount
                 ? std::numeric_limits<std::uint32_t>::max()
                 : *counter + amount;
}

}  // namespace

std::uint32_t skippedPeriods(double gap, double period) {
  if (!(gap > 1.5 * period)) {
    return 0;
  }
  const double skipped = std::round(gap / period) - 1.0;
  return skipped >= static_cast<double>(std::numeric_limits<std::uint32_t>::max())
             ? std::numeric_limits<std::uint32_t>::max()
             : static_cast<std::uint32_t>(skipped);
}

FollowerCycle::FollowerCycle(std::unique_ptr<DynamicFollowerController> controller,
                             const Eigen::VectorXd& separation, FollowerCycleSettings settings)
    : controller_(std::move(controller)), separation_(separation), settings_(settings) {
  if (!controller_ || separation.size() != controller_->stateDimension()) {
    throw std::invalid_argument("FollowerCycle: a controller and d of its state's size");
  }
  period_ = controller_->design().period;
  y_.resize(controller_->outputDimension());
}

FollowerCycle::~FollowerCycle() {
  delete offered_.exchange(nullptr);
  delete retired_.exchange(nullptr);
}

std::unique_ptr<DynamicFollowerController> FollowerCycle::offer(
    std::unique_ptr<DynamicFollowerController> controller) {
  if (!controller || controller->stateDimension() != controller_->stateDimension() ||
      controller->inputDimension() != controller_->inputDimension() ||
      controller->outputDimension() != controller_->outputDimension()) {
    throw std::invalid_argument("FollowerCycle::offer: a controller of the same model sizes");
  }
  return std::unique_ptr<DynamicFollowerController>(offered_.exchange(controller.release()));
}

std::unique_ptr<DynamicFollowerController> FollowerCycle::retired() {
  return std::unique_ptr<DynamicFollowerController>(retired_.exchange(nullptr));
}

void FollowerCycle::adoptOffered() {
  if (retired_.load(std::memory_order_acquire) != nullptr) {
    return;  // the previous one is not collected yet: adopt at a later tick
  }
  DynamicFollowerController* next = offered_.exchange(nullptr);
  if (next == nullptr) {
    return;
  }
  next->adoptStateOf(*controller_);
  retired_.store(controller_.release(), std::memory_order_release);
  controller_.reset(next);
}

void FollowerCycle::latchInputs() {
  if (measurement_.read()) {
    ever_measured_ = true;
  }
  if (leader_.read()) {
    ever_led_ = true;
  }
  if (own_state_.read()) {
    ever_own_state_ = true;
  }
}

void FollowerCycle::checkTimeline(std::int64_t now_ns) {
  // An input of the old timeline (received after now: ROS time went back) is not valid.
  have_measurement_ = ever_measured_ && measurement_.value().receipt_ns <= now_ns;
  have_leader_ = ever_led_ && leader_.value().receipt_ns <= now_ns;
  have_own_state_ = ever_own_state_ && own_state_.value().receipt_ns <= now_ns;
}

bool FollowerCycle::tickLatched(std::int64_t now_ns, std::int64_t steady_ns, double delay,
                                std::uint32_t skipped, FollowerCycleOutput* out) {
  out->stepped = false;
  stall_ = 0.0;
  time_.wentBack(now_ns);  // counted and reported (time_jump) by fillCounters()
  checkTimeline(now_ns);

  const double grace = 0.5 * settings_.measurement_timeout;
  // A stall: the tick ran late by a good part of the timeout on ROS time (delay), or the process
  // did not tick for that long on the steady clock (a simulated clock replayed after a stall
  // passes its periods one by one, so that each tick looks on time).
  const double gap =
      have_last_tick_steady_
          ? kNanosecond * static_cast<double>(steady_ns - last_tick_steady_ns_) - period_
          : 0.0;
  last_tick_steady_ns_ = steady_ns;
  have_last_tick_steady_ = true;
  // Measurements refused as stamped ahead of this clock since the tick before.
  const std::uint64_t future = future_measurements_.load(std::memory_order_relaxed);
  if (future != future_seen_) {
    future_seen_ = future;
    last_future_steady_ns_ = steady_ns;
    have_future_ = true;
  }
  const double stalled = std::max(delay, gap);
  if (stalled > grace) {
    // The measurements sent meanwhile are not read yet: wait for them. After a stall seen on the
    // steady clock alone, only while measurements are refused as future (a replaying clock; a
    // lockstep simulation that stood still with everyone else refuses none).
    resuming_ = true;
    wait_anchored_ = delay > grace;
    resumed_at_steady_ns_ = steady_ns;
    stall_began_steady_ns_ = steady_ns;
    wait_limit_ = std::max(settings_.measurement_timeout, stalled);
    sequence_at_stall_ = measurement_.value().sequence;
    stall_ = stalled;
  }
  if (resuming_) {
    // A measurement refused as future: this clock is still catching up, and the measurements
    // will be accepted once it has. Wait on from then, for at most wait_limit_ in all.
    if (have_future_ && last_future_steady_ns_ >= stall_began_steady_ns_ &&
        (!wait_anchored_ || last_future_steady_ns_ > resumed_at_steady_ns_)) {
      resumed_at_steady_ns_ = last_future_steady_ns_;
      wait_anchored_ = true;
    }
    const double quiet = kNanosecond * static_cast<double>(steady_ns - resumed_at_steady_ns_);
    const double waited = kNanosecond * static_cast<double>(steady_ns - stall_began_steady_ns_);
    if (measurement_.value().sequence == sequence_at_stall_ && wait_anchored_ && quiet < grace &&
        waited < wait_limit_) {
      addSaturated(&missed_periods_, skipped + 1);
      fillCounters(now_ns, out);
      return false;
    }
    resuming_ = false;
  }
  if (!settings_.measurement_trigger) {
    addSaturated(&missed_periods_, skipped);
    return step(now_ns, now_ns, delay, out);
  }
  // Measurement trigger: the measurements run the steps while they are fresh; a tick only
  // brakes once they are stale.
  const bool fresh = have_measurement_ &&
                     inputAge(now_ns, measurement_.value().stamp_ns,
                              measurement_.value().receipt_ns) <= settings_.measurement_timeout;
  if (ever_measured_ && !fresh) {
    return step(now_ns, now_ns, delay, out);
  }
  fillCounters(now_ns, out);
  return false;
}

bool FollowerCycle::stepOnLatchedMeasurement(std::int64_t now_ns, std::uint32_t skipped,
                                             FollowerCycleOutput* out) {
  checkTimeline(now_ns);
  if (!have_measurement_) {
    out->stepped = false;
    fillCounters(now_ns, out);
    return false;
  }
  addSaturated(&missed_periods_, skipped);
  const MeasurementSample& m = measurement_.value();
  return step(now_ns, m.stamp_ns, kNanosecond * static_cast<double>(now_ns - m.stamp_ns), out);
}

bool FollowerCycle::step(std::int64_t now_ns, std::int64_t stamp_ns, double delay,
                         FollowerCycleOutput* out) {
  FollowerInputAges ages;
  ages.have_measurement = ever_measured_;
  ages.measurement_age = have_measurement_ ? inputAge(stamp_ns, measurement_.value().stamp_ns,
                                                      measurement_.value().receipt_ns)
                                           : kNoInputAge;
  ages.have_leader = ever_led_;
  ages.leader_age = have_leader_
                        ? inputAge(stamp_ns, leader_.value().stamp_ns, leader_.value().receipt_ns)
                        : kNoInputAge;
  mode_ = selectFollowerMode(
      ages, FollowerTimeouts{settings_.measurement_timeout, settings_.leader_timeout});
  out->stepped = false;
  out->mode = mode_;
  if (mode_ == FollowerMode::kWaiting) {
    fillCounters(now_ns, out);
    return false;
  }
  ++steps_;
  tick_delay_ = delay;
  if (delay > 0.5 * period_) {
    addSaturated(&late_periods_, 1);
  }
  out->leader_fresh = have_leader_ && ages.leader_age <= settings_.leader_timeout;
  const bool use_leader = settings_.use_leader_input && out->leader_fresh;
  const ControllerDesign& design = controller_->design();
  const GenericDimensions::StateVector& state = measurement_.value().relative_state;
  out->xi = state - separation_;
  const Eigen::Index axes = design.parameters.model.position_dimension;
  out->distance = state.head(axes).norm();
  // The time headway (S1) acts from the own state while it is fresh; without it the step runs
  // the paper's constant spacing.
  const OwnStateSample& own = own_state_.value();
  out->own_state_fresh =
      design.parameters.time_headway > 0.0 && have_own_state_ &&
      inputAge(stamp_ns, own.stamp_ns, own.receipt_ns) <= settings_.measurement_timeout;
  DynamicStepInputs inputs;  // without a measurement the step runs the fallback
  if (mode_ != FollowerMode::kMeasurementLost) {
    y_.noalias() = design.parameters.model.C * out->xi;
    inputs.measurement.emplace(y_);
    if (out->own_state_fresh) {
      inputs.own_state.emplace(own.state);
    }
  }
  if (use_leader) {
    inputs.leader_input.emplace(leader_.value().acceleration);
  }
  const DynamicFollowerStatus* status = &controller_->step(inputs);
  out->stepped = true;
  out->stamp_ns = stamp_ns;
  out->steps = steps_;
  out->measurement_age = ages.measurement_age;
  out->leader_age = ages.leader_age;
  out->status = *status;
  fillCounters(now_ns, out);
  return true;
}

void FollowerCycle::fillCounters(std::int64_t now_ns, FollowerCycleOutput* out) const {
  out->now_ns = now_ns;
  out->mode = mode_;
  out->missed_periods = missed_periods_;
  out->late_periods = late_periods_;
  out->tick_delay = tick_delay_;
  out->time_jumps = time_.jumps();
  out->time_jump = time_.jump();
  out->stall = stall_;
  if (!out->stepped) {
    out->steps = steps_;
  }
  const ControllerDesign& design = controller_->design();
  out->xi_max = design.xi_max;
  out->xi_soft = design.xi_soft;
  out->perimeter = design.perimeter;
  out->acceleration_limit = design.parameters.acceleration_limit;
  out->jerk_limit = design.parameters.jerk_limit;
  out->tracker_enabled = design.parameters.tracker_enabled;
  out->time_headway = design.parameters.time_headway;
}

}  // namespace projection_collision_avoidance
