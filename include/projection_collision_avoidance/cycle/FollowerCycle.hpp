#pragma once

#include <algorithm>
#include <cstdint>
#include <limits>
#include <memory>
#include <mutex>
#include <optional>
#include <type_traits>
#include <utility>

#include "projection_collision_avoidance/core/DynamicFollowerController.hpp"
#include "projection_collision_avoidance/core/FollowerMode.hpp"
#include "projection_collision_avoidance/core/TurningSlot.hpp"
#include "projection_collision_avoidance/core/TypeDefs.hpp"
#include "projection_collision_avoidance/cycle/BarrierSensing.hpp"
#include "projection_collision_avoidance/cycle/ControllerHandover.hpp"
#include "projection_collision_avoidance/cycle/InputTimeline.hpp"
#include "projection_collision_avoidance/cycle/LatchedInputs.hpp"
#include "projection_collision_avoidance/cycle/NeighbourSensing.hpp"
#include "projection_collision_avoidance/cycle/PathSlot.hpp"
#include "projection_collision_avoidance/cycle/StallWait.hpp"
#include "projection_collision_avoidance/cycle/StepPacer.hpp"
#include "projection_collision_avoidance/cycle/TimeJumpWatch.hpp"
#include "projection_collision_avoidance/rt/LatestValue.hpp"
#include "projection_collision_avoidance/rt/PeriodicThread.hpp"

namespace projection_collision_avoidance {

/// Control periods skipped between two consecutive due times @p gap s apart (s): none up to 1.5
/// periods, else round(gap / period) - 1 (saturated).
std::uint32_t skippedPeriods(double gap, double period);

/// What the follower's control cycle needs besides the controller's design.
struct FollowerCycleSettings {
  double measurement_timeout = 0.5;  ///< s: an older measurement is stale
  double leader_timeout = 0.5;       ///< s: an older leader broadcast is stale
  bool use_leader_input = false;     ///< give the controller a fresh leader acceleration
  bool measurement_trigger = false;  ///< steps answer measurements (paced: StepPacer); ticks
                                     ///< only brake
  /// Turning slots (formation.slots: turning): the slot heading's generator (T1); empty: d fixed
  /// in the world.
  std::optional<SlotHeadingParameters> turning;
  /// Path slots (formation.slots: path): the convoy's reference (C1)-(C5); empty: no convoy.
  std::optional<ConvoyParameters> path;
  /// formation.neighbours: every step keeps out of the agents of the latest neighbour array
  /// (N1)-(N3), which is stale after measurement_timeout; empty: the target alone.
  std::optional<NeighbourCycleSettings> neighbours;
};

/// What a tick or step gives the outputs: the step's results when one ran, and the counters.
/// Fixed size: filling it allocates nothing.
struct FollowerCycleOutput {
  bool stepped = false;     ///< a control step ran (else: waiting, stalled, or a tick of the
                            ///< measurement trigger while the measurement is fresh)
  std::int64_t now_ns = 0;  ///< ROS time of the tick or measurement that gave this output
  /// the step's stamp: tick time, or the measurement's stamp; 1 ns after the step before when
  /// that is not later (a clock standing still, a measurement stamped as the one before), so that
  /// no two commands carry one stamp
  std::int64_t stamp_ns = 0;
  std::uint64_t steps = 0;  ///< control steps run since start, this one included
  FollowerMode mode = FollowerMode::kWaiting;
  bool leader_fresh = false;
  double measurement_age = 0.0;  ///< s at the stamp; +inf when none on this timeline
  double leader_age = 0.0;       ///< s at the stamp; +inf when none on this timeline
  /// The step used the own state: a time headway is in force and the own odometry was younger
  /// than the measurement timeout at the stamp (else the headway is left out this step).
  bool own_state_fresh = false;
  GenericDimensions::StateVector xi;  ///< x_target - x_i - D of the measurement used (m, m/s)
  /// D: d, or with turning slots d turned by the slot heading (T2) (m, m/s)
  GenericDimensions::StateVector slot;
  SlotHeadingSample slot_heading;  ///< theta, theta', theta'' of a turning slot (T1); else 0
  /// Turning slots: the step had the target's heading (own odometry and measurement fresh, the
  /// target faster than formation.turning.min_speed); else the slot stopped turning. Path slots:
  /// the step had the target's state (own odometry and measurement fresh); else the reference's
  /// goal held and the step braked
  bool heading_known = false;
  double distance = 0.0;         ///< ||p_target - p_i|| of that measurement (m)
  DynamicFollowerStatus status;  ///< the controller's step
  // The design in force (filled with or without a step).
  double xi_max = 0.0;              ///< (1 - alpha) ||d|| in force (m)
  double xi_soft = 0.0;             ///< xi_max / sqrt(1 + epsilon) in force (m)
  double perimeter = 0.0;           ///< alpha ||d|| in force (m)
  double acceleration_limit = 0.0;  ///< in force (m/s^2)
  double jerk_limit = 0.0;          ///< in force (m/s^3)
  bool tracker_enabled = false;     ///< in force
  double time_headway = 0.0;        ///< h in force (s); 0: constant spacing
  std::uint32_t missed_periods = 0;
  std::uint32_t late_periods = 0;
  /// measurement trigger: accepted measurements that ran no step since start, each too soon
  /// after the step before (StepPacer); the next step uses the latest
  std::uint32_t held_measurements = 0;
  double tick_delay = 0.0;       ///< s, of the latest step
  std::uint32_t time_jumps = 0;  ///< jumps back of ROS time since start
  double time_jump = 0.0;        ///< s (negative): the jump seen at this tick, else 0
  double stall = 0.0;            ///< s: a tick this late began a wait for input, else 0
  NeighbourReport neighbours;    ///< formation.neighbours: what the sensed agents did
  BarrierReport barriers;        ///< controller.safety_filter: what the barriers (B2) did
};

/// The follower's control cycle without ROS: it reads the latest accepted inputs from lock-free
/// slots the input side writes (measurement(), leader(), ownState()), decides the mode from their
/// ages, runs one step of the controller and fills a FollowerCycleOutput. With a time headway
/// (time_headway > 0) a step with a measurement uses the own state while it is younger than the
/// measurement timeout (StepInputs::own_state), else leaves the headway
/// out. With turning slots (FollowerCycleSettings::turning) the slot turns with the heading of the
/// target's velocity, its own (odometry) plus the measured relative velocity, (T1)-(T3): the first
/// step waits for the own state, which sets theta(0). With path slots (FollowerCycleSettings::path)
/// the slot is a reference point on the target's path, the target's state being the own
/// (odometry) plus the measured relative state (PathSlot); the first step waits for the own
/// state, and a step without a fresh own state brakes (mode measurement_lost). With
/// formation.neighbours (FollowerCycleSettings::neighbours) every step's command keeps out of the
/// agents of the latest neighbour array (NeighbourSensing, (N1)-(N3)): the first step waits for
/// one, and a step without one younger than the measurement timeout brakes (mode
/// measurement_lost). Nothing in tick() or
/// stepOnMeasurement() allocates, locks (except under the measurement trigger, whose steps run in
/// the measurement's callback, and a tick waits for a step running there) or makes a system call,
/// so that a real-time thread can run it.
///
/// Time: every call reads the ROS time `now_ns` after it has latched the inputs. An input is valid
/// while it was received at or before now (after a jump back of ROS time, those of the old timeline
/// are not, so the follower brakes until new ones arrive); its age is inputAge(), from
/// min(stamp, receipt), as InputTimeline::age() reports it, and +inf (kNoInputAge) when none.
/// A stalled process starts a wait in which ticks are skipped and counted as missed (StallWait).
///
/// Its parts, one job each: LatchedInputs (the slots, what was latched, which inputs are of this
/// timeline, their ages), TimeJumpWatch (ROS time going back), StallWait (the wait after a stall),
/// ControllerHandover (the controller in force and a new design's); the cycle itself picks the
/// mode, counts periods and steps.
class FollowerCycle {
 public:
  /// @param controller the controller, moved in
  /// @param separation d of this follower's slot (n entries)
  FollowerCycle(std::unique_ptr<DynamicFollowerController> controller,
                const Eigen::VectorXd& separation, FollowerCycleSettings settings);
  ~FollowerCycle();
  FollowerCycle(const FollowerCycle&) = delete;
  FollowerCycle& operator=(const FollowerCycle&) = delete;

  /// The slot the measurement callback writes (one writer thread).
  LatestValue<MeasurementSample>& measurement() { return inputs_.measurementSlot(); }
  /// The slot the leader-broadcast callback writes (one writer thread).
  LatestValue<LeaderSample>& leader() { return inputs_.leaderSlot(); }
  /// The slot the own odometry's callback writes (one writer thread; time headway only).
  LatestValue<OwnStateSample>& ownState() { return inputs_.ownStateSlot(); }
  /// The slot the neighbour array's callback writes (one writer thread; formation.neighbours).
  LatestValue<NeighbourSample>& neighbours() { return inputs_.neighbourSlot(); }

  /// A tick of the fixed-rate loop at steady (monotonic) time @p steady_ns, @p delay s after it
  /// was due, with @p skipped periods skipped before it. It latches the inputs first and then
  /// reads ROS time with @p ros_now (a callable returning ns), so that every input it reads was
  /// received at or before the time it steps at; an input received after it is then one of an old
  /// timeline, never one that arrived while the tick began. Timer trigger: a step stamped now.
  /// Measurement trigger: a braking step once the measurement is stale, else nothing.
  /// @return whether @p out got a step (out->stepped); the counters are filled either way
  template <typename RosNow,
            typename = std::enable_if_t<std::is_invocable_r_v<std::int64_t, RosNow&>>>
  bool tick(RosNow&& ros_now, std::int64_t steady_ns, double delay, std::uint32_t skipped,
            FollowerCycleOutput* out) {
    std::unique_lock<std::mutex> lock(trigger_mutex_, std::defer_lock);
    if (settings_.measurement_trigger) {
      lock.lock();  // a measurement's step may be running in its callback: wait for it
    }
    handover_.adopt();
    inputs_.latch();
    return tickLatched(ros_now(), steady_ns, delay, skipped, out);
  }
  /// tick() at the given ROS time @p now_ns.
  bool tick(std::int64_t now_ns, std::int64_t steady_ns, double delay, std::uint32_t skipped,
            FollowerCycleOutput* out) {
    return tick([now_ns] { return now_ns; }, steady_ns, delay, skipped, out);
  }
  /// tick() for a PeriodicTick of the real-time thread (PeriodicThread, SharedTicker), the one
  /// path by which those threads tick: delay (s) from the tick's due and actual steady times, the
  /// periods it skipped (saturated to 32 bits), ROS time from @p ros_now once the inputs are
  /// latched.
  template <typename RosNow,
            typename = std::enable_if_t<std::is_invocable_r_v<std::int64_t, RosNow&>>>
  bool tickOn(const PeriodicTick& tick, RosNow&& ros_now, FollowerCycleOutput* out) {
    const double delay = 1e-9 * static_cast<double>(tick.actual - tick.expected);
    const std::uint64_t most = std::numeric_limits<std::uint32_t>::max();
    return this->tick(std::forward<RosNow>(ros_now), tick.actual, delay,
                      static_cast<std::uint32_t>(std::min(tick.skipped, most)), out);
  }
  /// tick() where ROS time is the steady clock (wall time that does not jump).
  bool tick(std::int64_t now_ns, double delay, std::uint32_t skipped, FollowerCycleOutput* out) {
    return tick(now_ns, now_ns, delay, skipped, out);
  }

  /// The step answering the measurement just written to measurement() (measurement trigger),
  /// stamped with its stamp, at the ROS time @p ros_now gives (ns) once the inputs are latched;
  /// @p skipped periods since the one before. Paced by the measurements' stamps (StepPacer): one
  /// that comes too soon after the step before runs none (held_measurements), and the next step
  /// uses the latest measurement. A step Delta t < T after the step before (their stamps) may
  /// change the command by jerk_limit Delta t only (StepInputs::period_fraction).
  /// @return whether @p out got a step
  template <typename RosNow,
            typename = std::enable_if_t<std::is_invocable_r_v<std::int64_t, RosNow&>>>
  bool stepOnMeasurement(RosNow&& ros_now, std::uint32_t skipped, FollowerCycleOutput* out) {
    const std::lock_guard<std::mutex> lock(trigger_mutex_);
    handover_.adopt();
    inputs_.latch();
    return stepOnLatchedMeasurement(ros_now(), skipped, out);
  }
  /// stepOnMeasurement() at the given ROS time @p now_ns.
  bool stepOnMeasurement(std::int64_t now_ns, std::uint32_t skipped, FollowerCycleOutput* out) {
    return stepOnMeasurement([now_ns] { return now_ns; }, skipped, out);
  }

  /// The input side refused a measurement stamped ahead of this process's clock (any thread,
  /// lock-free). While a tick waits after a stall, each one extends the wait: the clock is still
  /// catching up, and measurements will be accepted once it has.
  void noteFutureMeasurement() { stall_wait_.noteFutureMeasurement(); }

  /// Hands over a controller for a new design (built elsewhere, e.g. by reconfiguration); a
  /// coming tick adopts it, carrying over the estimate and previous command, once the controller
  /// it replaced last time has been collected with retired(). A controller offered before and
  /// not yet adopted is returned for disposal.
  std::unique_ptr<DynamicFollowerController> offer(
      std::unique_ptr<DynamicFollowerController> controller) {
    return handover_.offer(std::move(controller));
  }
  /// The controller replaced by the last adoption, for disposal off the control thread.
  std::unique_ptr<DynamicFollowerController> retired() { return handover_.retired(); }

  /// Design in force at the last tick (read it from the control thread only, or before start).
  const ControllerDesign& design() const { return handover_.current().design(); }

 private:
  /// One control step at ROS time @p now_ns, stamped @p stamp_ns, @p delay s after it was due.
  bool step(std::int64_t now_ns, std::int64_t stamp_ns, double delay, FollowerCycleOutput* out);
  bool tickLatched(std::int64_t now_ns, std::int64_t steady_ns, double delay, std::uint32_t skipped,
                   FollowerCycleOutput* out);
  bool stepOnLatchedMeasurement(std::int64_t now_ns, std::uint32_t skipped,
                                FollowerCycleOutput* out);
  /// D and u_r of this step into @p out and slot_acceleration_ (turning slots: from the heading
  /// of the target's velocity when the own state is fresh at @p stamp_ns); false when the first
  /// step must wait for the own state.
  bool turnSlot(std::int64_t stamp_ns, const GenericDimensions::StateVector& state,
                FollowerCycleOutput* out);
  /// D and u_r of a path slot (PathSlot); false when the first step must wait for the own state.
  /// A step without a fresh own state is one of mode measurement_lost. The own controlled point
  /// is moved to the measurement's stamp at its velocity (by at most measurement_timeout).
  bool pathSlot(std::int64_t stamp_ns, const GenericDimensions::StateVector& state,
                FollowerCycleOutput* out);
  /// formation.neighbours: the half-spaces of the step stamped @p stamp_ns from the latest
  /// neighbour array, the target's perimeter @p target_perimeter (m); nullptr without the
  /// section, and when that array is stale (the step then brakes: mode measurement_lost).
  const CommandProjection* constrainByNeighbours(std::int64_t stamp_ns, double target_perimeter,
                                                 FollowerCycleOutput* out);
  /// controller.safety_filter (of the design in force): the barriers of a measured step from the
  /// relative state @p state, the target's acceleration @p leader when known (null otherwise) and
  /// the step's neighbours; nullptr without the filter.
  const SafetyFilter* senseBarriers(const GenericDimensions::StateVector& state,
                                    const Eigen::Ref<const Eigen::VectorXd>* leader,
                                    bool neighbours_given);
  /// The counters and the design in force into @p out (whether or not a step ran).
  void fillCounters(std::int64_t now_ns, FollowerCycleOutput* out) const;
  /// Notes ROS time @p now_ns: a jump back is counted, and the stamps start afresh.
  void noteTime(std::int64_t now_ns);

  ControllerHandover handover_;  ///< the controller in force, and a new design's
  GenericDimensions::StateVector separation_;
  FollowerCycleSettings settings_;
  std::optional<SlotHeading> slot_heading_;           ///< theta (T1) of a turning slot
  bool heading_started_ = false;                      ///< theta(0) set by the first step
  std::optional<PathSlot> path_slot_;                 ///< r (C1)-(C5) of a path slot
  std::optional<NeighbourSensing> neighbours_;        ///< (N1)-(N3) with formation.neighbours
  std::optional<BarrierSensing> barriers_;            ///< (B2) with controller.safety_filter
  GenericDimensions::InputVector slot_acceleration_;  ///< u_r (T3) of the step
  GenericDimensions::InputVector own_position_;       ///< path slots: own point at the stamp
  double period_ = 0.0;
  std::mutex trigger_mutex_;  ///< measurement trigger only: callback steps vs braking ticks
  LatchedInputs inputs_;
  TimeJumpWatch time_;    ///< jumps back of ROS time at the ticks and measurement steps
  StallWait stall_wait_;  ///< the wait for input after a stall

  FollowerMode mode_ = FollowerMode::kWaiting;
  std::uint64_t steps_ = 0;
  std::int64_t last_stamp_ns_ = 0;  ///< the latest step's stamp on this timeline
  bool have_stamp_ = false;         ///< a step ran on this timeline
  std::uint32_t missed_periods_ = 0;
  std::uint32_t late_periods_ = 0;
  std::uint32_t held_measurements_ = 0;
  StepPacer pacer_;  ///< measurement trigger: the steps no faster than the control rate
  double tick_delay_ = 0.0;
  GenericDimensions::OutputVector y_;
};

}  // namespace projection_collision_avoidance
