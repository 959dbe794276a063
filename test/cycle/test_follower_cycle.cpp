/// The follower's control cycle and its real-time hand-offs, without ROS: the control thread
/// allocates and frees nothing over 10,000 ticks with every input (the own state of a time
/// headway included) and output in use; modes, time jumps and stalls; the own state used only
/// while fresh; the lock-free slot, queue and doorbell.

#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <memory>
#include <thread>

#include <gtest/gtest.h>

#include "projection_collision_avoidance/core/ControllerDesign.hpp"
#include "projection_collision_avoidance/cycle/FollowerCycle.hpp"
#include "projection_collision_avoidance/rt/Handoff.hpp"
#include "projection_collision_avoidance/rt/LatestValue.hpp"

#include "AllocationCounter.hpp"
#include "TestScenarios.hpp"

namespace projection_collision_avoidance {
namespace {

constexpr std::int64_t kMs = 1000000;  // ns
constexpr std::int64_t kStart = 1000 * 1000 * kMs;

/// Run 2's controller at 1 kHz, with a time headway of @p time_headway s (S1).
ControllerDesign run2Design(double time_headway = 0.0) {
  ControllerParameters p = testing::paperParameters();  // Run 2's controller
  p.control_rate = 1000.0;
  p.acceleration_limit = 6.0;
  p.jerk_limit = 500.0;
  p.time_headway = time_headway;
  return ControllerDesign::create(p);
}

std::unique_ptr<FollowerCycle> makeCycle(FollowerCycleSettings settings = {},
                                         double time_headway = 0.0) {
  const ControllerDesign design = run2Design(time_headway);
  return std::make_unique<FollowerCycle>(std::make_unique<DynamicFollowerController>(design),
                                         design.parameters.separation, settings);
}

MeasurementSample measurementAt(std::int64_t stamp_ns, std::uint64_t sequence, double gap) {
  MeasurementSample m;
  m.stamp_ns = stamp_ns;
  m.receipt_ns = stamp_ns;
  m.sequence = sequence;
  m.relative_state.setZero(2);
  m.relative_state << gap, 0.0;
  return m;
}

OwnStateSample ownStateAt(std::int64_t stamp_ns, std::uint64_t sequence, double velocity) {
  OwnStateSample own;
  own.stamp_ns = stamp_ns;
  own.receipt_ns = stamp_ns;
  own.sequence = sequence;
  own.state.setZero(2);
  own.state << 0.001 * static_cast<double>(sequence), velocity;
  return own;
}

/// Ticks every millisecond (ROS and steady time alike, on time) from @p from_ns to @p to_ns, both
/// included; returns the number of steps, with @p out the last tick's output.
int tickEachMs(FollowerCycle* cycle, std::int64_t from_ns, std::int64_t to_ns,
               FollowerCycleOutput* out) {
  int steps = 0;
  for (std::int64_t t = from_ns; t <= to_ns; t += kMs) {
    steps += cycle->tick(t, 0.0, 0, out) ? 1 : 0;
  }
  return steps;
}

TEST(FollowerCycle, TheControlThreadAllocatesAndFreesNothing) {
  FollowerCycleSettings settings;
  settings.use_leader_input = true;
  std::unique_ptr<FollowerCycle> cycle = makeCycle(settings, 0.5);
  Handoff<FollowerCycleOutput, 64> outputs;
  constexpr int kTicks = 12000;
  std::atomic<std::int64_t> clock{kStart};
  std::atomic<std::int64_t> inputs_at{0};  // the latest clock reading the inputs thread answered
  std::atomic<bool> done{false};

  // The subscriber's side: measurements (with a 1 s outage from tick 4000), leader broadcasts and
  // the own odometry. It writes while the control thread ticks; the control thread lets it fall
  // at most kLagTicks behind, so that how the two are scheduled (a loaded machine can hold one
  // thread off for tens of milliseconds) cannot age the inputs into a timeout.
  constexpr std::int64_t kLagTicks = 5;
  std::thread inputs([&] {
    std::uint64_t sequence = 0;
    std::int64_t last = 0;
    while (!done) {
      const std::int64_t now = clock.load();
      const bool outage = now > kStart + 4000 * kMs && now < kStart + 5000 * kMs;
      if (now != last && !outage) {
        cycle->measurement().write(
            measurementAt(now, ++sequence, 5.0 + 0.5 * std::sin(1e-9 * now)));
        LeaderSample leader;
        leader.stamp_ns = leader.receipt_ns = now;
        leader.acceleration.setConstant(1, -0.5);
        cycle->leader().write(leader);
        cycle->ownState().write(ownStateAt(now, sequence, 1.0 + 0.1 * std::cos(1e-9 * now)));
      }
      if (now != last) {
        last = now;
        inputs_at.store(now);
      }
      std::this_thread::yield();
    }
  });
  // The publisher's side: takes every output (and would build messages from it). A publisher
  // held off the processor lets the handoff drop outputs (counted), so the steps are counted on
  // the control thread, where they are made.
  long published = 0;
  std::thread publisher([&] {
    FollowerCycleOutput out;
    std::uint32_t seen = outputs.count();
    for (bool last_round = false; !last_round;) {
      last_round = done.load();  // after done, one more round takes what is left
      while (outputs.pop(&out)) {
        ++published;
      }
      if (!last_round) {
        seen = outputs.wait(seen, 10 * kMs);
      }
    }
  });

  // The control thread: ticks, a reconfiguration adopted half way, every output handed off.
  long allocations = -1;
  long frees = -1;
  long steps_seen = 0;
  long headway_steps = 0;
  std::unique_ptr<DynamicFollowerController> offered =
      std::make_unique<DynamicFollowerController>(run2Design(0.5));
  std::thread control([&] {
    FollowerCycleOutput out;
    const long allocations_before = testing::threadAllocationCount();
    const long frees_before = testing::threadFreeCount();
    for (int k = 1; k <= kTicks; ++k) {
      while (inputs_at.load() < clock.load() - kLagTicks * kMs) {
        std::this_thread::yield();
      }
      const std::int64_t now = clock.fetch_add(kMs) + kMs;
      if (k == 6000) {
        cycle->offer(std::move(offered));  // built on another thread; adopted by a tick
      }
      // The path the node's real-time thread ticks by (FollowerLoop::onThreadTick()), on time.
      PeriodicTick tick;
      tick.index = static_cast<std::uint64_t>(k);
      tick.expected = tick.actual = now;
      tick.period = kMs;
      cycle->tickOn(
          tick, [now] { return now; }, &out);
      steps_seen += out.stepped ? 1 : 0;
      headway_steps += out.stepped && out.own_state_fresh ? 1 : 0;
      outputs.post(out);
      std::this_thread::sleep_for(std::chrono::microseconds(50));
    }
    allocations = testing::threadAllocationCount() - allocations_before;
    frees = testing::threadFreeCount() - frees_before;
  });
  control.join();
  done = true;
  outputs.wake();
  inputs.join();
  publisher.join();

  EXPECT_EQ(allocations, 0);
  EXPECT_EQ(frees, 0);
  EXPECT_NE(cycle->retired(), nullptr);  // the reconfiguration was adopted
  EXPECT_GE(published + static_cast<long>(outputs.dropped()), kTicks);
  EXPECT_GE(steps_seen, 10000);
  EXPECT_GE(headway_steps, 9000);  // the time headway stepped with the own state
}

TEST(FollowerCycle, ModesFromTheInputsAges) {
  std::unique_ptr<FollowerCycle> cycle = makeCycle();
  FollowerCycleOutput out;
  EXPECT_FALSE(cycle->tick(kStart, 0.0, 0, &out));
  EXPECT_EQ(out.mode, FollowerMode::kWaiting);
  cycle->measurement().write(measurementAt(kStart, 1, 5.0));
  ASSERT_TRUE(cycle->tick(kStart + kMs, 0.0, 0, &out));
  EXPECT_EQ(out.mode, FollowerMode::kTracking);
  EXPECT_NEAR(out.measurement_age, 0.001, 1e-12);
  EXPECT_NEAR(out.distance, 5.0, 1e-12);
  // Older than the 0.5 s timeout: the braking fallback.
  EXPECT_EQ(tickEachMs(cycle.get(), kStart + 2 * kMs, kStart + 600 * kMs, &out), 599);
  EXPECT_EQ(out.mode, FollowerMode::kMeasurementLost);
  EXPECT_TRUE(out.status.fallback);
}

TEST(FollowerCycle, ATimeHeadwayStepsWithTheOwnStateWhileItIsFresh) {
  std::unique_ptr<FollowerCycle> cycle = makeCycle({}, 0.5);
  FollowerCycleOutput out;
  cycle->measurement().write(measurementAt(kStart, 1, 5.0));
  ASSERT_TRUE(cycle->tick(kStart + kMs, 0.0, 0, &out));  // no odometry yet: no headway
  EXPECT_FALSE(out.own_state_fresh);
  EXPECT_EQ(out.status.headway_command.norm(), 0.0);
  EXPECT_EQ(out.time_headway, 0.5);
  cycle->ownState().write(ownStateAt(kStart + kMs, 1, 2.0));
  cycle->measurement().write(measurementAt(kStart + 2 * kMs, 2, 5.0));
  ASSERT_TRUE(cycle->tick(kStart + 2 * kMs, 0.0, 0, &out));
  EXPECT_TRUE(out.own_state_fresh);
  EXPECT_GT(out.status.headway_command.norm(), 0.0);
  // The odometry older than the measurement timeout (0.5 s): the headway is left out.
  tickEachMs(cycle.get(), kStart + 3 * kMs, kStart + 599 * kMs, &out);
  cycle->measurement().write(measurementAt(kStart + 600 * kMs, 3, 5.0));
  ASSERT_TRUE(cycle->tick(kStart + 600 * kMs, 0.0, 0, &out));
  EXPECT_EQ(out.mode, FollowerMode::kTracking);
  EXPECT_FALSE(out.own_state_fresh);
  EXPECT_EQ(out.status.headway_command.norm(), 0.0);
  // Of an old timeline after ROS time went back: not used either.
  cycle->ownState().write(ownStateAt(kStart + 601 * kMs, 2, 2.0));
  cycle->measurement().write(measurementAt(kStart - 1000 * kMs, 4, 5.0));
  ASSERT_TRUE(cycle->tick(kStart - 999 * kMs, 0.0, 0, &out));
  EXPECT_EQ(out.mode, FollowerMode::kTracking);
  EXPECT_FALSE(out.own_state_fresh);
}

TEST(FollowerCycle, WithoutATimeHeadwayTheOwnStateIsNotUsed) {
  std::unique_ptr<FollowerCycle> cycle = makeCycle();
  FollowerCycleOutput out;
  cycle->ownState().write(ownStateAt(kStart, 1, 2.0));
  cycle->measurement().write(measurementAt(kStart, 1, 5.0));
  ASSERT_TRUE(cycle->tick(kStart + kMs, 0.0, 0, &out));
  EXPECT_FALSE(out.own_state_fresh);
  EXPECT_EQ(out.status.headway_command.norm(), 0.0);
  EXPECT_EQ(out.time_headway, 0.0);
}

TEST(FollowerCycle, AJumpBackOfTimeInvalidatesTheOldTimelinesInputs) {
  std::unique_ptr<FollowerCycle> cycle = makeCycle();
  FollowerCycleOutput out;
  cycle->measurement().write(measurementAt(kStart, 1, 5.0));
  ASSERT_TRUE(cycle->tick(kStart + kMs, 0.0, 0, &out));
  EXPECT_EQ(out.mode, FollowerMode::kTracking);
  ASSERT_TRUE(cycle->tick(kStart - 100000 * kMs, 0.0, 0, &out));  // 100 s earlier
  EXPECT_EQ(out.time_jumps, 1U);
  EXPECT_LT(out.time_jump, -99.0);
  EXPECT_EQ(out.mode, FollowerMode::kMeasurementLost);
  EXPECT_TRUE(std::isinf(out.measurement_age));
  cycle->measurement().write(measurementAt(kStart - 99999 * kMs, 2, 5.0));
  ASSERT_TRUE(cycle->tick(kStart - 99998 * kMs, 0.0, 0, &out));
  EXPECT_EQ(out.mode, FollowerMode::kTracking);
  EXPECT_GE(out.measurement_age, 0.0);
}

TEST(FollowerCycle, NoTwoStepsCarryOneStampWhileTheClockStandsStill) {
  // A bursty simulated clock: ticks at one time. Each step's stamp lies 1 ns after the one
  // before; once the clock moves on, the stamps are its times again.
  std::unique_ptr<FollowerCycle> cycle = makeCycle();
  FollowerCycleOutput out;
  cycle->measurement().write(measurementAt(kStart, 1, 5.0));
  for (std::int64_t i = 0; i < 3; ++i) {
    ASSERT_TRUE(cycle->tick(kStart + kMs, 0.0, 0, &out));
    EXPECT_EQ(out.stamp_ns, kStart + kMs + i);
  }
  ASSERT_TRUE(cycle->tick(kStart + 2 * kMs, 0.0, 0, &out));
  EXPECT_EQ(out.stamp_ns, kStart + 2 * kMs);
  // Time going back starts a new timeline: its own time again, not 1 ns after the old one.
  cycle->measurement().write(measurementAt(kStart - 1000 * kMs, 2, 5.0));
  ASSERT_TRUE(cycle->tick(kStart - 999 * kMs, 0.0, 0, &out));
  EXPECT_EQ(out.stamp_ns, kStart - 999 * kMs);
}

TEST(FollowerCycle, AMeasurementArrivingAsATickBeginsIsNotTakenForAnOldTimeline) {
  // The input thread writes a measurement received 1 us after the control thread read ROS time.
  // Latched with that earlier time, it would look received in the future (of an old timeline)
  // and the tick would brake; the tick reads the time after latching, so it steps on the one
  // before and takes the new one at the next tick. Both triggers.
  for (const bool measurement_trigger : {false, true}) {
    FollowerCycleSettings settings;
    settings.measurement_trigger = measurement_trigger;
    std::unique_ptr<FollowerCycle> cycle = makeCycle(settings);
    FollowerCycleOutput out;
    cycle->measurement().write(measurementAt(kStart, 1, 5.0));
    if (measurement_trigger) {
      ASSERT_TRUE(cycle->stepOnMeasurement(kStart, 0, &out));
    } else {
      ASSERT_TRUE(cycle->tick(kStart + kMs, 0.0, 0, &out));
    }
    EXPECT_EQ(out.mode, FollowerMode::kTracking);
    const std::int64_t now = kStart + 2 * kMs;
    const auto clock_read_as_a_measurement_arrives = [&cycle, now] {
      cycle->measurement().write(measurementAt(now + 1000, 2, 5.0));
      return now;
    };
    EXPECT_EQ(cycle->tick(clock_read_as_a_measurement_arrives, now, 0.0, 0, &out),
              !measurement_trigger)
        << "measurement trigger: " << measurement_trigger;
    EXPECT_EQ(out.mode, FollowerMode::kTracking) << "measurement trigger: " << measurement_trigger;
    EXPECT_FALSE(out.status.fallback);
    if (measurement_trigger) {
      ASSERT_TRUE(cycle->stepOnMeasurement(now + 2000, 0, &out));
      EXPECT_EQ(out.stamp_ns, now + 1000);  // the step answering it
    } else {
      ASSERT_TRUE(cycle->tick(now + kMs, 0.0, 0, &out));
      EXPECT_NEAR(out.measurement_age, 0.001 - 1e-6, 1e-12);  // the new one
    }
    EXPECT_EQ(out.mode, FollowerMode::kTracking);
  }
}

TEST(FollowerCycle, AfterAStallItWaitsForTheInputSentMeanwhile) {
  std::unique_ptr<FollowerCycle> cycle = makeCycle();
  FollowerCycleOutput out;
  cycle->measurement().write(measurementAt(kStart, 1, 5.0));
  ASSERT_TRUE(cycle->tick(kStart + kMs, 0.0, 0, &out));
  // 2 s late: no step until a new measurement, though the old one is 2 s old.
  EXPECT_FALSE(cycle->tick(kStart + 2001 * kMs, 2.0, 199, &out));
  EXPECT_GT(out.stall, 1.9);
  EXPECT_EQ(out.missed_periods, 200U);
  EXPECT_FALSE(cycle->tick(kStart + 2002 * kMs, 0.0, 0, &out));
  cycle->measurement().write(measurementAt(kStart + 2002 * kMs, 2, 5.0));
  ASSERT_TRUE(cycle->tick(kStart + 2003 * kMs, 0.0, 0, &out));
  EXPECT_EQ(out.mode, FollowerMode::kTracking);
  // Without a new measurement the wait ends after half the timeout: then the fallback.
  EXPECT_FALSE(cycle->tick(kStart + 5000 * kMs, 2.0, 0, &out));
  EXPECT_EQ(tickEachMs(cycle.get(), kStart + 5001 * kMs, kStart + 5249 * kMs, &out), 0);
  ASSERT_TRUE(cycle->tick(kStart + 5250 * kMs, 0.0, 0, &out));
  EXPECT_EQ(out.mode, FollowerMode::kMeasurementLost);
}

TEST(FollowerCycle, TheWaitAfterAStallIsMeasuredOnTheSteadyClock) {
  // Simulated time catches up when a stalled process resumes: 1.4 s of ROS time within 1 ms of
  // steady time must not end the wait for the measurements sent meanwhile.
  std::unique_ptr<FollowerCycle> cycle = makeCycle();
  FollowerCycleOutput out;
  const std::int64_t steady = 1000 * kMs;
  cycle->measurement().write(measurementAt(kStart, 1, 5.0));
  ASSERT_TRUE(cycle->tick(kStart + kMs, steady, 0.0, 0, &out));
  EXPECT_FALSE(cycle->tick(kStart + 2001 * kMs, steady + 2000 * kMs, 2.0, 199, &out));
  for (int k = 1; k <= 140; ++k) {  // ROS time +1.4 s, steady time +0.14 ms
    EXPECT_FALSE(
        cycle->tick(kStart + (2001 + 10 * k) * kMs, steady + 2000 * kMs + k * 1000, 0.0, 0, &out))
        << k;
  }
  cycle->measurement().write(measurementAt(kStart + 3400 * kMs, 2, 5.0));
  ASSERT_TRUE(cycle->tick(kStart + 3410 * kMs, steady + 2001 * kMs, 0.0, 0, &out));
  EXPECT_EQ(out.mode, FollowerMode::kTracking);
  // Half the timeout of steady time without a measurement ends the wait: then the fallback.
  EXPECT_FALSE(cycle->tick(kStart + 6000 * kMs, steady + 4500 * kMs, 2.0, 0, &out));
  for (int k = 1; k < 250; ++k) {
    EXPECT_FALSE(cycle->tick(kStart + (6000 + k) * kMs, steady + (4500 + k) * kMs, 0.0, 0, &out));
  }
  ASSERT_TRUE(cycle->tick(kStart + 6250 * kMs, steady + 4750 * kMs, 0.0, 0, &out));
  EXPECT_EQ(out.mode, FollowerMode::kMeasurementLost);
}

TEST(FollowerCycle, AClockReplayedPeriodByPeriodAfterAStallIsAStallToo) {
  // A simulated clock replays the 2 s the process stood still period by period: each tick looks
  // on time on ROS time, but 2 s of steady time passed since the one before. The newest
  // measurements are refused as stamped ahead of the replaying clock (noteFutureMeasurement()):
  // the wait goes on past half the timeout until the clock has caught up and one is accepted.
  std::unique_ptr<FollowerCycle> cycle = makeCycle();
  FollowerCycleOutput out;
  const std::int64_t steady = 1000 * kMs;
  cycle->measurement().write(measurementAt(kStart, 1, 5.0));
  ASSERT_TRUE(cycle->tick(kStart + kMs, steady, 0.0, 0, &out));
  cycle->noteFutureMeasurement();
  EXPECT_FALSE(cycle->tick(kStart + 2 * kMs, steady + 2001 * kMs, 0.0, 0, &out));
  EXPECT_GT(out.stall, 1.9);
  for (int k = 1; k <= 400; ++k) {  // 400 ms of steady time, ROS time replaying 2 s
    cycle->noteFutureMeasurement();
    EXPECT_FALSE(cycle->tick(kStart + (2 + 5 * k) * kMs, steady + (2001 + k) * kMs, 0.0, 0, &out))
        << k;
  }
  cycle->measurement().write(measurementAt(kStart + 2002 * kMs, 2, 5.0));
  ASSERT_TRUE(cycle->tick(kStart + 2003 * kMs, steady + 2402 * kMs, 0.0, 0, &out));
  EXPECT_EQ(out.mode, FollowerMode::kTracking);
}

TEST(FollowerCycle, WithoutRefusalsAsFutureAStallOnTheSteadyClockAloneDoesNotWait) {
  // A lockstep simulation that stood still with everyone else: 2 s of steady time between two
  // ticks one period apart on ROS time, no measurement refused: the tick steps at once.
  std::unique_ptr<FollowerCycle> cycle = makeCycle();
  FollowerCycleOutput out;
  const std::int64_t steady = 1000 * kMs;
  cycle->measurement().write(measurementAt(kStart, 1, 5.0));
  ASSERT_TRUE(cycle->tick(kStart + kMs, steady, 0.0, 0, &out));
  ASSERT_TRUE(cycle->tick(kStart + 2 * kMs, steady + 2001 * kMs, 0.0, 0, &out));
  EXPECT_EQ(out.mode, FollowerMode::kTracking);
  EXPECT_GT(out.stall, 1.9);  // reported all the same
}

TEST(FollowerCycle, RefusalsAsFutureExtendTheWaitAtMostAsLongAsTheStall) {
  // A sender whose stamps are always refused as future: the wait after a 2 s stall ends after
  // max(measurement timeout, 2 s) of steady time, then the fallback brakes.
  std::unique_ptr<FollowerCycle> cycle = makeCycle();
  FollowerCycleOutput out;
  cycle->measurement().write(measurementAt(kStart, 1, 5.0));
  ASSERT_TRUE(cycle->tick(kStart + kMs, 0.0, 0, &out));
  EXPECT_FALSE(cycle->tick(kStart + 2001 * kMs, 2.0, 199, &out));
  int steps = 0;
  std::int64_t first_step = 0;
  for (std::int64_t t = kStart + 2002 * kMs; t <= kStart + 4100 * kMs; t += kMs) {
    cycle->noteFutureMeasurement();
    if (cycle->tick(t, 0.0, 0, &out) && steps++ == 0) {
      first_step = t;
    }
  }
  EXPECT_EQ(first_step, kStart + 4001 * kMs);  // 2 s after the stall was seen
  EXPECT_EQ(out.mode, FollowerMode::kMeasurementLost);
  EXPECT_EQ(steps, 100);
}

TEST(FollowerCycle, TheMeasurementTriggerStepsOnMeasurementsAndBrakesOnTicks) {
  FollowerCycleSettings settings;
  settings.measurement_trigger = true;
  std::unique_ptr<FollowerCycle> cycle = makeCycle(settings);
  FollowerCycleOutput out;
  cycle->measurement().write(measurementAt(kStart, 1, 5.0));
  ASSERT_TRUE(cycle->stepOnMeasurement(kStart + 2 * kMs, 0, &out));
  EXPECT_EQ(out.stamp_ns, kStart);
  EXPECT_NEAR(out.tick_delay, 0.002, 1e-12);
  EXPECT_FALSE(cycle->tick(kStart + 10 * kMs, 0.0, 0, &out));  // fresh: the tick only counts
  // Stale from 0.5 s on: the ticks brake.
  EXPECT_EQ(tickEachMs(cycle.get(), kStart + 11 * kMs, kStart + 500 * kMs, &out), 0);
  EXPECT_EQ(tickEachMs(cycle.get(), kStart + 501 * kMs, kStart + 700 * kMs, &out), 200);
  EXPECT_EQ(out.mode, FollowerMode::kMeasurementLost);
}

TEST(LatestValue, TheReaderGetsTheNewestCompleteValue) {
  LatestValue<std::array<std::int64_t, 16>> slot;
  std::atomic<bool> done{false};
  std::thread writer([&] {
    std::array<std::int64_t, 16> value{};
    for (std::int64_t k = 1; k <= 200000; ++k) {
      value.fill(k);
      slot.write(value);
    }
    done = true;
  });
  std::int64_t last = 0;
  long torn = 0;
  while (!done || slot.read()) {
    if (slot.read()) {
      const auto& value = slot.value();
      for (const std::int64_t entry : value) {
        torn += entry != value[0] ? 1 : 0;
      }
      EXPECT_GE(value[0], last);
      last = value[0];
    }
  }
  writer.join();
  slot.read();
  EXPECT_EQ(torn, 0);
  EXPECT_EQ(slot.value()[0], 200000);
}

TEST(Handoff, KeepsOrderDropsWhenFullAndWakesTheWorker) {
  Handoff<int, 4> handoff;
  for (int k = 1; k <= 6; ++k) {
    handoff.post(k);
  }
  EXPECT_EQ(handoff.dropped(), 2U);
  int item = 0;
  for (int k = 1; k <= 4; ++k) {
    ASSERT_TRUE(handoff.pop(&item));
    EXPECT_EQ(item, k);
  }
  EXPECT_FALSE(handoff.pop(&item));
  const std::uint32_t seen = handoff.count();
  std::thread poster([&] {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    handoff.post(7);
  });
  const auto start = std::chrono::steady_clock::now();
  handoff.wait(seen, 5000 * kMs);  // woken by the post, long before the 5 s timeout
  const auto waited = std::chrono::steady_clock::now() - start;
  poster.join();
  EXPECT_LT(waited, std::chrono::seconds(2));
  ASSERT_TRUE(handoff.pop(&item));
  EXPECT_EQ(item, 7);
}

}  // namespace
}  // namespace projection_collision_avoidance
