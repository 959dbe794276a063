#include "projection_collision_avoidance/cycle/FollowerCycle.hpp"

#include <algorithm>
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
    : handover_(std::move(controller)),
      separation_(separation),
      settings_(settings),
      period_(handover_.current().design().period),
      stall_wait_(settings.measurement_timeout, period_),
      pacer_(period_) {
  if (separation.size() != handover_.current().stateDimension()) {
    throw std::invalid_argument("FollowerCycle: a controller and d of its state's size");
  }
  y_.resize(handover_.current().outputDimension());
  slot_acceleration_.setZero(handover_.current().inputDimension());
  if (settings_.turning) {
    slot_heading_.emplace(*settings_.turning, period_);
  }
  if (settings_.path) {
    own_position_.setZero(handover_.current().inputDimension());
    path_slot_.emplace(
        *settings_.path, period_, separation_,
        static_cast<int>(handover_.current().design().parameters.model.position_dimension));
  }
  if (settings_.neighbours) {
    const ControllerParameters& p = handover_.current().design().parameters;
    neighbours_.emplace(*settings_.neighbours, static_cast<int>(p.model.position_dimension),
                        p.acceleration_limit);
  }
  barriers_.emplace(
      static_cast<int>(handover_.current().design().parameters.model.position_dimension));
}

FollowerCycle::~FollowerCycle() = default;

bool FollowerCycle::tickLatched(std::int64_t now_ns, std::int64_t steady_ns, double delay,
                                std::uint32_t skipped, FollowerCycleOutput* out) {
  out->stepped = false;
  noteTime(now_ns);
  inputs_.checkTimeline(now_ns);
  if (stall_wait_.holds(steady_ns, delay, inputs_.measurement().sequence)) {
    addSaturated(&missed_periods_, skipped + 1);
    fillCounters(now_ns, out);
    return false;
  }
  if (!settings_.measurement_trigger) {
    addSaturated(&missed_periods_, skipped);
    return step(now_ns, now_ns, delay, out);
  }
  // Measurement trigger: the measurements run the steps while they are fresh; a tick only
  // brakes once they are stale.
  const bool fresh = inputs_.measurementAge(now_ns) <= settings_.measurement_timeout;
  if (inputs_.everMeasured() && !fresh) {
    return step(now_ns, now_ns, delay, out);
  }
  fillCounters(now_ns, out);
  return false;
}

bool FollowerCycle::stepOnLatchedMeasurement(std::int64_t now_ns, std::uint32_t skipped,
                                             FollowerCycleOutput* out) {
  noteTime(now_ns);
  inputs_.checkTimeline(now_ns);
  if (!inputs_.haveMeasurement()) {
    out->stepped = false;
    fillCounters(now_ns, out);
    return false;
  }
  addSaturated(&missed_periods_, skipped);
  const MeasurementSample& m = inputs_.measurement();
  if (!pacer_.admit(m.stamp_ns)) {  // too soon after the step before: latched for the next
    addSaturated(&held_measurements_, 1);
    out->stepped = false;
    fillCounters(now_ns, out);
    return false;
  }
  return step(now_ns, m.stamp_ns, kNanosecond * static_cast<double>(now_ns - m.stamp_ns), out);
}

bool FollowerCycle::step(std::int64_t now_ns, std::int64_t stamp_ns, double delay,
                         FollowerCycleOutput* out) {
  FollowerInputAges ages;
  ages.have_measurement = inputs_.everMeasured();
  ages.measurement_age = inputs_.measurementAge(stamp_ns);
  ages.have_leader = inputs_.everLed();
  ages.leader_age = inputs_.leaderAge(stamp_ns);
  mode_ = selectFollowerMode(
      ages, FollowerTimeouts{settings_.measurement_timeout, settings_.leader_timeout});
  out->stepped = false;
  out->mode = mode_;
  const GenericDimensions::StateVector& state = inputs_.measurement().relative_state;
  // The first step waits for the first neighbour array too (formation.neighbours).
  const bool neighbours_unknown = neighbours_ && !inputs_.everNeighboured();
  if (mode_ == FollowerMode::kWaiting || neighbours_unknown || !turnSlot(stamp_ns, state, out)) {
    mode_ = FollowerMode::kWaiting;
    out->mode = mode_;
    fillCounters(now_ns, out);
    return false;
  }
  ++steps_;
  tick_delay_ = delay;
  if (delay > 0.5 * period_) {
    addSaturated(&late_periods_, 1);
  }
  out->leader_fresh = inputs_.haveLeader() && ages.leader_age <= settings_.leader_timeout;
  const bool use_leader = settings_.use_leader_input && out->leader_fresh;
  DynamicFollowerController& controller = handover_.current();
  const ControllerDesign& design = controller.design();
  out->xi = state - out->slot;
  const Eigen::Index axes = design.parameters.model.position_dimension;
  out->distance = state.head(axes).norm();
  // The time headway (S1) acts from the own state while it is fresh; without it the step runs
  // the paper's constant spacing.
  out->own_state_fresh = design.parameters.time_headway > 0.0 &&
                         inputs_.ownStateAge(stamp_ns) <= settings_.measurement_timeout;
  // No two commands carry one stamp; under the measurement trigger the rate limit allows the
  // change of the time since the step before (their stamps), a period at most.
  const std::int64_t stamp =
      have_stamp_ && stamp_ns <= last_stamp_ns_ ? last_stamp_ns_ + 1 : stamp_ns;
  DynamicStepInputs inputs;  // without a measurement the step runs the fallback
  out->barriers = BarrierReport{};
  out->barriers.configured = design.parameters.safety_filter.has_value();
  inputs.command_constraints = constrainByNeighbours(stamp_ns, design.perimeter, out);
  if (settings_.measurement_trigger && have_stamp_) {
    inputs.period_fraction =
        std::min(1.0, kNanosecond * static_cast<double>(stamp - last_stamp_ns_) / period_);
  }
  if (mode_ != FollowerMode::kMeasurementLost) {
    y_.noalias() = design.parameters.model.C * out->xi;
    inputs.measurement.emplace(y_);
    if (out->own_state_fresh) {
      inputs.own_state.emplace(inputs_.ownState().state);
    }
  }
  if (use_leader) {
    inputs.leader_input.emplace(inputs_.leader().acceleration);
  }
  if (inputs.measurement) {
    inputs.safety_filter =
        senseBarriers(state, inputs.leader_input ? &*inputs.leader_input : nullptr,
                      inputs.command_constraints != nullptr);
  }
  if (slot_heading_ || path_slot_) {
    inputs.slot_acceleration.emplace(slot_acceleration_);
  }
  const DynamicFollowerStatus* status = &controller.step(inputs);
  out->stepped = true;
  out->stamp_ns = stamp;
  last_stamp_ns_ = stamp;
  have_stamp_ = true;
  out->steps = steps_;
  out->measurement_age = ages.measurement_age;
  out->leader_age = ages.leader_age;
  out->status = *status;
  if (inputs.safety_filter != nullptr) {
    barriers_->report(*status, neighbours_ ? &inputs_.neighbours() : nullptr, &out->barriers);
  } else if (neighbours_ && inputs.command_constraints) {
    neighbours_->report(inputs_.neighbours(), *status, &out->neighbours);
  }
  fillCounters(now_ns, out);
  return true;
}

const CommandProjection* FollowerCycle::constrainByNeighbours(std::int64_t stamp_ns,
                                                              double target_perimeter,
                                                              FollowerCycleOutput* out) {
  NeighbourReport& report = out->neighbours;
  report = NeighbourReport{};
  if (!neighbours_) {
    return nullptr;
  }
  report.configured = true;
  report.age = inputs_.neighboursAge(stamp_ns);
  report.fresh = report.age <= settings_.measurement_timeout;
  if (!report.fresh) {  // where the others are is not known: brake
    mode_ = FollowerMode::kMeasurementLost;
    out->mode = mode_;
    report.nearest = std::numeric_limits<double>::infinity();
    report.smallest_barrier = std::numeric_limits<double>::infinity();
    return nullptr;
  }
  const NeighbourSample& sample = inputs_.neighbours();
  const double ahead = kNanosecond * static_cast<double>(stamp_ns - sample.stamp_ns);
  return &neighbours_->constrain(sample, ahead, settings_.measurement_timeout, target_perimeter);
}

const SafetyFilter* FollowerCycle::senseBarriers(const GenericDimensions::StateVector& state,
                                                 const Eigen::Ref<const Eigen::VectorXd>* leader,
                                                 bool neighbours_given) {
  const ControllerDesign& design = handover_.current().design();
  const std::optional<SafetyFilterParameters>& filter = design.parameters.safety_filter;
  if (!filter || !design.parameters.model.isDoubleIntegrator()) {
    return nullptr;
  }
  const bool with_neighbours = neighbours_given && neighbours_;
  return &barriers_->sense(
      state, leader, design.perimeter, filter->rate, with_neighbours ? &*neighbours_ : nullptr,
      with_neighbours ? &inputs_.neighbours() : nullptr,
      settings_.neighbours ? settings_.neighbours->parameters.neighbour_acceleration : 0.0);
}

bool FollowerCycle::turnSlot(std::int64_t stamp_ns, const GenericDimensions::StateVector& state,
                             FollowerCycleOutput* out) {
  out->slot = separation_;
  out->heading_known = false;
  if (path_slot_) {
    return pathSlot(stamp_ns, state, out);
  }
  if (!slot_heading_) {
    return true;
  }
  const Eigen::Index axes = handover_.current().design().parameters.model.position_dimension;
  const bool own_fresh = inputs_.ownStateAge(stamp_ns) <= settings_.measurement_timeout;
  if (!heading_started_ && !own_fresh) {
    return false;  // theta(0) comes from the target's first heading (or 0 without one)
  }
  std::optional<double> heading;
  if (own_fresh && mode_ != FollowerMode::kMeasurementLost) {
    // v_target = v_i + (v_target - v_i): the own controlled point's velocity plus the measured.
    const auto& own = inputs_.ownState().controlled_velocity;
    heading = velocityHeading(own(0) + state(axes), own(1) + state(axes + 1),
                              settings_.turning->min_speed);
  }
  if (!heading_started_) {
    slot_heading_->reset(heading.value_or(0.0));
    heading_started_ = true;
  }
  out->heading_known = heading.has_value();
  out->slot_heading = slot_heading_->tick(heading);
  turningSlotOffset(separation_, static_cast<int>(axes), out->slot_heading, &out->slot);
  turningSlotAcceleration(separation_, static_cast<int>(axes), out->slot_heading,
                          &slot_acceleration_);
  return true;
}

bool FollowerCycle::pathSlot(std::int64_t stamp_ns, const GenericDimensions::StateVector& state,
                             FollowerCycleOutput* out) {
  const bool own_fresh = inputs_.ownStateAge(stamp_ns) <= settings_.measurement_timeout;
  const bool known = own_fresh && mode_ != FollowerMode::kMeasurementLost;
  if (!path_slot_->started() && !known) {
    return false;  // the path starts at the target's first known position
  }
  if (!own_fresh) {
    mode_ = FollowerMode::kMeasurementLost;  // no target state: brake
    out->mode = mode_;
  }
  // The own controlled point at the measurement's stamp, at its own velocity: the two inputs of
  // the target's position (own + measured) may come from different samples (an odometry slower
  // than the measurement, or one delayed behind it).
  const OwnStateSample& own = inputs_.ownState();
  const double lag =
      std::clamp(kNanosecond * static_cast<double>(inputs_.measurement().stamp_ns - own.stamp_ns),
                 -settings_.measurement_timeout, settings_.measurement_timeout);
  own_position_.noalias() = own.controlled_position + lag * own.controlled_velocity;
  // The reference keeps the measurement's time (the step's without one): a step that reads the
  // measurement of the step before, as a timer tick ahead of the sample it waits for does, finds
  // r where that step left it.
  const std::int64_t time = known ? inputs_.measurement().stamp_ns : stamp_ns;
  path_slot_->step(time, known, own_position_, own.controlled_velocity, state, &out->slot,
                   &slot_acceleration_);
  out->heading_known = known;
  return true;
}

void FollowerCycle::noteTime(std::int64_t now_ns) {
  // Counted and reported (time_jump) by fillCounters(); a new timeline's stamps start afresh.
  if (time_.wentBack(now_ns)) {
    have_stamp_ = false;
    pacer_.reset();
    if (path_slot_) {
      path_slot_->restartClock();
    }
  }
}

void FollowerCycle::fillCounters(std::int64_t now_ns, FollowerCycleOutput* out) const {
  out->now_ns = now_ns;
  out->mode = mode_;
  out->missed_periods = missed_periods_;
  out->late_periods = late_periods_;
  out->held_measurements = held_measurements_;
  out->tick_delay = tick_delay_;
  out->time_jumps = time_.jumps();
  out->time_jump = time_.jump();
  out->stall = stall_wait_.stall();
  if (!out->stepped) {
    out->steps = steps_;
  }
  const ControllerDesign& design = handover_.current().design();
  out->xi_max = design.xi_max;
  out->xi_soft = design.xi_soft;
  out->perimeter = design.perimeter;
  out->acceleration_limit = design.parameters.acceleration_limit;
  out->jerk_limit = design.parameters.jerk_limit;
  out->tracker_enabled = design.parameters.tracker_enabled;
  out->time_headway = design.parameters.time_headway;
}

}  // namespace projection_collision_avoidance
