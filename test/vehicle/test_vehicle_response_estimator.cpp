/// VehicleResponseEstimator against simulated vehicles that show, every update interval, the
/// command in force a delay earlier (scaled by a gain): the update interval, the delay and the
/// realised fraction found; no fraction while the commands are constant; the delay kept among
/// near-equal candidates; time going back; unusable options refused by key.

#include <cmath>
#include <limits>
#include <string>

#include <gtest/gtest.h>

#include "projection_collision_avoidance/core/ParameterError.hpp"
#include "projection_collision_avoidance/vehicle/VehicleResponseEstimator.hpp"

namespace projection_collision_avoidance {
namespace {

constexpr double kPeriod = 0.01;

AxisVector vec(double x) { return AxisVector::Constant(1, x); }

/// A vehicle observed every `update` s whose velocity is gain · (the command in force `delay`
/// s earlier), driven by commands c(t) = amplitude sin(2π f t) sent every period.
struct VehicleRun {
  double update = 0.1;
  double delay = 0.1;
  double gain = 1.0;
  double amplitude = 0.5;
  double frequency = 0.5;
  double duration = 10.0;

  VehicleResponse operator()(VehicleResponseEstimator* estimator) const {
    CommandHistory history(256, 1);
    double previous = 0.0;
    double next_update = update;
    const int steps = static_cast<int>(std::lround(duration / kPeriod));
    for (int k = 0; k < steps; ++k) {
      const double t = k * kPeriod;
      if (t >= next_update - 1e-9) {
        AxisVector shown = vec(0.0);
        history.commandBefore(t - delay, &shown);
        estimator->observe(gain * shown, t, history);
        next_update += update;
      }
      const double command = amplitude * std::sin(2.0 * M_PI * frequency * t);
      // Commands go out just after the state of their instant was taken.
      history.push(t + 1e-6, vec(command), vec(command - previous));
      previous = command;
    }
    return estimator->response();
  }
};

VehicleResponseEstimator estimator(double max_delay = 0.3) {
  ResponseEstimatorOptions o;
  o.period = kPeriod;
  o.max_delay = max_delay;
  return VehicleResponseEstimator(o);
}

std::string refusedKey(const ResponseEstimatorOptions& o) {
  try {
    VehicleResponseEstimator e(o);
  } catch (const ParameterError& error) {
    return error.key();
  }
  return "";
}

TEST(VehicleResponseEstimator, RefusesUnusableOptions) {
  ResponseEstimatorOptions o;
  EXPECT_EQ(refusedKey(o), "");
  o.period = 0.0;
  EXPECT_EQ(refusedKey(o), "vehicle.velocity.period");
  o = ResponseEstimatorOptions();
  o.max_delay = -0.1;
  EXPECT_EQ(refusedKey(o), "vehicle.velocity.max_delay");
  o.max_delay = 2.56;  // 256 periods of 10 ms
  EXPECT_EQ(refusedKey(o), "vehicle.velocity.max_delay");
  o.max_delay = 2.55;
  EXPECT_EQ(refusedKey(o), "");
  o.averaging_time = 0.0;
  EXPECT_EQ(refusedKey(o), "vehicle.velocity.averaging_time");
  o = ResponseEstimatorOptions();
  o.min_acceleration = -0.01;
  EXPECT_EQ(refusedKey(o), "vehicle.velocity.min_acceleration");
  o = ResponseEstimatorOptions();
  o.segment = 0.0;
  EXPECT_EQ(refusedKey(o), "vehicle.velocity.segment");
}

TEST(VehicleResponseEstimator, FindsTheHoldAndTheDelayOfAVehicleSlowerThanItsCommands) {
  for (const double update : {0.01, 0.05, 0.1}) {
    for (const double delay : {0.0, 0.01, 0.1, 0.2}) {
      VehicleResponseEstimator e = estimator();
      VehicleRun run;
      run.update = update;
      run.delay = delay;
      const VehicleResponse r = run(&e);
      EXPECT_NEAR(r.update_interval, update, 1e-6) << update << " " << delay;
      EXPECT_NEAR(r.delay, delay, 1e-9) << update << " " << delay;
      EXPECT_NEAR(r.realised_fraction, 1.0, 0.02) << update << " " << delay;
    }
  }
}

TEST(VehicleResponseEstimator, MeasuresTheFractionAWeakVehicleRealises) {
  VehicleResponseEstimator e = estimator();
  VehicleRun run;
  run.gain = 0.6;
  const VehicleResponse r = run(&e);
  // The delay of least error assumes a vehicle that realises its commands: with a gain of 0.6 it
  // comes out 0.08 s for the true 0.1 s, and the fraction is still measured.
  EXPECT_NEAR(r.delay, run.delay, 0.025);
  EXPECT_NEAR(r.realised_fraction, 0.6, 0.02);
}

TEST(VehicleResponseEstimator, SaysNothingOfTheFractionWhileTheCommandsAreConstant) {
  VehicleResponseEstimator e = estimator();
  VehicleRun run;
  run.frequency = 0.0;  // every command zero
  const VehicleResponse r = run(&e);
  EXPECT_TRUE(std::isnan(r.realised_fraction));
  EXPECT_EQ(r.delay, 0.0);  // all candidates equal: the first one stays
  EXPECT_GT(r.observations, 90U);
}

/// A vehicle at rest after a manoeuvre: its velocity noise (±2 mm/s) with no command asking for
/// anything does not move the fraction measured while it manoeuvred.
TEST(VehicleResponseEstimator, RestAfterAManoeuvreKeepsTheFraction) {
  VehicleResponseEstimator e = estimator();
  VehicleRun run;
  run.duration = 5.0;
  const double manoeuvring = run(&e).realised_fraction;
  ASSERT_NEAR(manoeuvring, 1.0, 0.02);
  CommandHistory history(256, 1);
  history.push(5.0, vec(0.0), vec(0.0));
  for (int k = 1; k <= 100; ++k) {  // 10 s at rest, a state every 0.1 s
    const double t = 5.0 + 0.1 * k;
    history.push(t + 1e-6, vec(0.0), vec(0.0));
    e.observe(vec(k % 2 == 0 ? 0.002 : -0.002), t, history);
  }
  EXPECT_EQ(e.response().realised_fraction, manoeuvring);
}

TEST(VehicleResponseEstimator, ALongerDelayThanItConsidersIsNotInvented) {
  VehicleResponseEstimator e = estimator(0.05);
  VehicleRun run;
  run.delay = 0.2;
  const VehicleResponse r = run(&e);
  EXPECT_LE(r.delay, 0.05);
}

TEST(VehicleResponseEstimator, TimeGoingBackStartsAfresh) {
  VehicleResponseEstimator e = estimator();
  VehicleRun run;
  run(&e);
  ASSERT_GT(e.response().observations, 10U);
  CommandHistory history(4, 1);
  e.observe(vec(0.0), 1.0, history);  // far before the run's last change
  EXPECT_EQ(e.response().observations, 1U);
  EXPECT_TRUE(std::isnan(e.response().update_interval));
  e.observe(vec(std::numeric_limits<double>::quiet_NaN()), 2.0, history);  // ignored
  EXPECT_EQ(e.response().observations, 1U);
}

}  // namespace
}  // namespace projection_collision_avoidance
