/// VelocityCommandIntegrator: the anchor (measured when fresh, at its age limit and one past it;
/// the previous command otherwise), the lead that makes a lagging vehicle gain a T per period,
/// no wind-up against a vehicle saturating at 1 m/s, the speed limit, refused inputs, and the
/// unicycle's limits fed back so that integration without measurements does not wind up.

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <utility>

#include <gtest/gtest.h>

#include "projection_collision_avoidance/core/ParameterError.hpp"
#include "projection_collision_avoidance/vehicle/UnicycleLookAhead.hpp"
#include "projection_collision_avoidance/vehicle/VelocityCommandIntegrator.hpp"

#include "EigenTestHelpers.hpp"

namespace projection_collision_avoidance {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

AxisVector vec(double x) { return AxisVector::Constant(1, x); }
AxisVector vec(double x, double y) {
  AxisVector v(2);
  v << x, y;
  return v;
}

VelocityIntegratorOptions options(int axes, double max_speed = kInf, double max_age = 0.125,
                                  double lag = 0.0) {
  VelocityIntegratorOptions o;
  o.axes = axes;
  o.max_speed = max_speed;
  o.max_measurement_age = max_age;
  o.velocity_lag = lag;
  return o;
}

std::string refusedKey(const VelocityIntegratorOptions& o) {
  try {
    VelocityCommandIntegrator integrator(o);
  } catch (const ParameterError& e) {
    return e.key();
  }
  return "";
}

TEST(VelocityCommandIntegrator, RefusesUnusableOptions) {
  EXPECT_EQ(refusedKey(options(0)), "vehicle.velocity.axes");
  EXPECT_EQ(refusedKey(options(4)), "vehicle.velocity.axes");
  EXPECT_EQ(refusedKey(options(2, 0.0)), "vehicle.velocity.max_speed");
  EXPECT_EQ(refusedKey(options(2, kNaN)), "vehicle.velocity.max_speed");
  EXPECT_EQ(refusedKey(options(2, kInf, -1.0)), "vehicle.velocity.max_measurement_age");
  EXPECT_EQ(refusedKey(options(2, kInf, kInf)), "vehicle.velocity.max_measurement_age");
  EXPECT_EQ(refusedKey(options(2, kInf, 0.1, -0.1)), "vehicle.velocity.velocity_lag");
  EXPECT_EQ(refusedKey(options(3, 2.0, 0.0, 0.0)), "");
}

TEST(VelocityCommandIntegrator, LeadIsThePeriodWithoutLagAndTauPlusHalfAPeriodForALongOne) {
  EXPECT_EQ(velocityLead(0.01, 0.0), 0.01);
  EXPECT_NEAR(velocityLead(0.01, 0.2), 0.01 / (1.0 - std::exp(-0.05)), 1e-15);
  EXPECT_NEAR(velocityLead(0.01, 100.0), 100.0 + 0.005, 1e-6);
  EXPECT_NEAR(velocityLead(0.01, 1e-6), 0.01, 1e-15);  // e^(−10^4) = 0
  for (double lag = 0.001; lag < 10.0; lag *= 1.7) {
    EXPECT_GE(velocityLead(0.01, lag), 0.01);
    EXPECT_LT(velocityLead(0.01, lag), velocityLead(0.01, lag * 1.7));
  }
}

TEST(VelocityCommandIntegrator, AnchorsOnAFreshMeasurementElseOnThePreviousCommand) {
  VelocityCommandIntegrator integrator(options(2));
  // No measurement: integrates from rest.
  VelocityCommand c = integrator.step(vec(1.0, -2.0), 0.5, 0.0);
  EXPECT_EQ(c.anchor, VelocityAnchor::kPreviousCommand);
  EXPECT_MATRIX_NEAR(c.velocity, vec(0.5, -1.0), 0.0);
  c = integrator.step(vec(1.0, -2.0), 0.5, 0.5);
  EXPECT_MATRIX_NEAR(c.velocity, vec(1.0, -2.0), 0.0);
  // A measurement taken at 1.0 s is fresh until 1.125 s, and from 0.875 s. The command sent at
  // 1.0 s is not in it yet: at 1.125 s it is added to the anchor. At 0.875 s time went back:
  // the commands sent "later" are forgotten.
  ASSERT_TRUE(integrator.measure(vec(3.0, 4.0), 1.0));
  const std::pair<double, AxisVector> steps[] = {
      {1.0, vec(3.125, 3.75)}, {1.125, vec(3.25, 3.5)}, {0.875, vec(3.125, 3.75)}};
  for (const auto& [now, expected] : steps) {
    c = integrator.step(vec(0.5, -1.0), 0.25, now);
    EXPECT_EQ(c.anchor, VelocityAnchor::kMeasured) << now;
    EXPECT_MATRIX_NEAR(c.velocity, expected, 0.0);
  }
  c = integrator.step(vec(0.5, -1.0), 0.25, std::nextafter(1.125, kInf));
  EXPECT_EQ(c.anchor, VelocityAnchor::kPreviousCommand);
  EXPECT_MATRIX_NEAR(c.velocity, vec(3.25, 3.5), 0.0);
  c = integrator.step(vec(0.5, -1.0), 0.25, std::nextafter(0.875, -kInf));
  EXPECT_EQ(c.anchor, VelocityAnchor::kPreviousCommand);
  c = integrator.step(vec(0.0, 0.0), 0.25, kNaN);  // an unknown time: not fresh
  EXPECT_EQ(c.anchor, VelocityAnchor::kPreviousCommand);
}

/// A 1-D vehicle whose velocity loop cannot exceed 1 m/s: it reaches min(v_cmd, 1) each period.
TEST(VelocityCommandIntegrator, NoWindUpAgainstAVehicleSaturatingAtOneMeterPerSecond) {
  const double T = 0.01;
  const double a = 2.0;
  VelocityCommandIntegrator anchored(options(1, kInf, 0.05));
  VelocityCommandIntegrator integrating(options(1, kInf, 0.05));  // never given a measurement
  double v_anchored = 0.0;
  double v_integrating = 0.0;
  double largest = 0.0;
  for (int k = 0; k < 500; ++k) {  // 5 s pushing forward
    const double now = k * T;
    ASSERT_TRUE(anchored.measure(vec(v_anchored), now));
    const double command = anchored.step(vec(a), T, now).velocity(0);
    largest = std::max(largest, command);
    v_anchored = std::min(command, 1.0);
    v_integrating = std::min(integrating.step(vec(a), T, now).velocity(0), 1.0);
  }
  EXPECT_LE(largest, 1.0 + a * T + 1e-12);
  EXPECT_NEAR(anchored.last().velocity(0), 1.0 + a * T, 1e-12);
  EXPECT_NEAR(integrating.last().velocity(0), 10.0, 1e-9);  // what anchoring avoids: 10 m/s
  // The push reverses: the anchored command drops below what the vehicle does at once, the
  // wound-up one stays above 1 m/s for (10 − 1) / 2 = 4.5 s.
  int integrating_saturated = 0;
  for (int k = 500; k < 1000; ++k) {
    const double now = k * T;
    ASSERT_TRUE(anchored.measure(vec(v_anchored), now));
    const double before = v_anchored;
    v_anchored = std::min(anchored.step(vec(-a), T, now).velocity(0), 1.0);
    EXPECT_NEAR(v_anchored, before - a * T, 1e-12);
    v_integrating = std::min(integrating.step(vec(-a), T, now).velocity(0), 1.0);
    integrating_saturated += v_integrating == 1.0 ? 1 : 0;
  }
  EXPECT_NEAR(v_anchored, 1.0 - 5.0 * a, 1e-9);
  EXPECT_GE(integrating_saturated, 449);
}

/// A vehicle with a first-order velocity loop, v' = (v_cmd − v) / τ, sampled every T.
TEST(VelocityCommandIntegrator, LeadMakesALaggingVehicleGainATPerPeriod) {
  const double T = 0.01;
  const double tau = 0.2;
  const double decay = std::exp(-T / tau);
  // τ configured; not configured with D estimated; not configured with D = 0 (the measured
  // velocity taken as the command in force).
  for (int variant = 0; variant < 3; ++variant) {
    const double lag = variant == 0 ? tau : 0.0;
    VelocityIntegratorOptions o = options(1, kInf, 0.05, lag);
    o.delay = variant == 2 ? 0.0 : -1.0;
    VelocityCommandIntegrator integrator(o);
    double v = 0.3;
    double gained = 0.0;
    for (int k = 0; k < 100; ++k) {
      ASSERT_TRUE(integrator.measure(vec(v), k * T));
      const double command = integrator.step(vec(1.5), T, k * T).velocity(0);
      const double next = command + (v - command) * decay;
      gained = next - v;
      v = next;
    }
    if (variant == 0) {
      EXPECT_NEAR(gained, 1.5 * T, 1e-12);  // the acceleration asked for
      EXPECT_NEAR(v, 0.3 + 1.5, 1e-10);
    } else if (variant == 1) {
      // The lag read as a delay of about τ: most of it, though not all (a lag is not a delay).
      EXPECT_GT(gained, 0.6 * 1.5 * T);
      EXPECT_NEAR(integrator.delay(), tau, 0.1);
    } else {
      EXPECT_LT(gained, 0.05 * 1.5 * T);  // v + a T: only 1 − e^(−T/τ) ≈ 5 % of it
    }
  }
}

/// The lagging vehicle measured a period late (its odometry arrives after the command of its
/// own instant): the command of that period, not shown yet, is added as what it asks of the
/// vehicle, a T, not as its lead a h, and the vehicle still gains a T per period.
TEST(VelocityCommandIntegrator, ALaggingVehicleMeasuredAPeriodLateGainsATPerPeriod) {
  const double T = 0.01;
  const double tau = 0.1;
  const double decay = std::exp(-T / tau);
  VelocityCommandIntegrator integrator(options(1, kInf, 0.05, tau));
  double v = 0.3;
  double v_before = 0.3;  // the velocity a period ago: what the measurement shows
  double gained = 0.0;
  double largest_gain = 0.0;
  for (int k = 1; k < 200; ++k) {
    ASSERT_TRUE(integrator.measure(vec(v_before), (k - 1) * T));
    const double command = integrator.step(vec(1.5), T, k * T).velocity(0);
    const double next = command + (v - command) * decay;
    gained = next - v;
    largest_gain = std::max(largest_gain, gained);
    v_before = v;
    v = next;
  }
  EXPECT_NEAR(gained, 1.5 * T, 1e-9);      // the acceleration asked for
  EXPECT_LE(largest_gain, 1.5 * T * 1.5);  // no overshoot from counting the lead as a gain
}

TEST(VelocityCommandIntegrator, SpeedLimitKeepsTheDirection) {
  VelocityCommandIntegrator integrator(options(2, 1.5));
  ASSERT_TRUE(integrator.measure(vec(1.0, 1.0), 0.0));
  const VelocityCommand c = integrator.step(vec(10.0, 0.0), 0.1, 0.0);  // (2, 1) before the limit
  EXPECT_TRUE(c.limited);
  EXPECT_NEAR(c.velocity.norm(), 1.5, 1e-15);
  EXPECT_LE(c.velocity.norm(), 1.5);
  EXPECT_MATRIX_NEAR(c.velocity, vec(2.0, 1.0) * (1.5 / std::sqrt(5.0)), 1e-15);
  // Integrating without measurements, the limited command is the state: it never grows past it.
  for (int k = 1; k < 100; ++k) {
    EXPECT_LE(integrator.step(vec(10.0, 0.0), 0.1, 10.0).velocity.norm(), 1.5);
  }
  const VelocityCommand back = integrator.step(vec(-5.0, 0.0), 0.1, 10.0);
  EXPECT_FALSE(back.limited);
  EXPECT_LT(back.velocity.norm(), 1.5);
}

TEST(VelocityCommandIntegrator, RefusedInputsHoldTheAnchor) {
  VelocityCommandIntegrator integrator(options(2, 2.0));
  EXPECT_FALSE(integrator.measure(vec(kNaN, 0.0), 0.0));
  EXPECT_FALSE(integrator.measure(vec(1.0), 0.0));  // one axis of two
  EXPECT_FALSE(integrator.measure(vec(1.0, 0.0), kInf));
  ASSERT_TRUE(integrator.measure(vec(1.0, 0.5), 0.0));
  // Each an acceleration and a period: NaN, T = 0, T < 0, T infinite, one axis of two, and an
  // a h that overflows.
  const std::pair<AxisVector, double> refused[] = {{vec(kNaN, 0.0), 0.1}, {vec(1.0, 1.0), 0.0},
                                                   {vec(1.0, 1.0), -0.1}, {vec(1.0, 1.0), kInf},
                                                   {vec(1.0), 0.1},       {vec(1e308, 0.0), 1e10}};
  for (const auto& [a, T] : refused) {
    const VelocityCommand c = integrator.step(a, T, 0.0);
    EXPECT_TRUE(c.refused);
    EXPECT_MATRIX_NEAR(c.velocity, vec(1.0, 0.5), 0.0);
  }
  integrator.reset();
  const VelocityCommand c = integrator.step(vec(1.0, 0.0), 0.1, 0.0);
  EXPECT_EQ(c.anchor, VelocityAnchor::kPreviousCommand);
  EXPECT_MATRIX_NEAR(c.velocity, vec(0.1, 0.0), 1e-17);
}

/// A vehicle slower than the controller: its state changes every P = 10 T (a physics step), when
/// its velocity becomes the command it was sent before the previous change (actuation_steps 1)
/// or before this one (0); its odometry is republished every T with a fresh stamp. Returns the
/// velocity gained per second over 2 s of a steady push @p a, divided by a.
double heldVehicleRealises(VelocityCommandIntegrator& integrator, bool dated, int actuation_steps,
                           double a) {
  const double T = 0.01;
  const int hold = 10;
  double v = 0.0;
  double pending = 0.0;  // the command the next physics step applies (actuation_steps 1)
  double latest = 0.0;   // the latest command sent
  double changed_at = 0.0;
  double v_start = 0.0;
  for (int k = 0; k <= 400; ++k) {
    const double now = k * T;
    if (k % hold == 0) {
      v = actuation_steps == 0 ? latest : pending;
      pending = latest;
      changed_at = now;
    }
    if (k == 200) {
      v_start = v;
    }
    EXPECT_TRUE(dated ? integrator.measure(vec(v), now, changed_at)
                      : integrator.measure(vec(v), now));
    latest = integrator.step(vec(a), T, now).velocity(0);
  }
  return (v - v_start) / 2.0 / a;
}

TEST(VelocityCommandIntegrator, AVehicleSlowerThanTheControllerRealisesTheAcceleration) {
  for (int actuation_steps : {0, 1}) {
    VelocityCommandIntegrator integrator(options(1, kInf, 0.25));
    const double realised = heldVehicleRealises(integrator, true, actuation_steps, 0.5);
    EXPECT_NEAR(realised, 1.0, 0.1) << actuation_steps;
    const VehicleResponse& response = integrator.response();
    EXPECT_NEAR(response.update_interval, 0.1, 1e-9);
    EXPECT_NEAR(response.realised_fraction, 1.0, 0.1) << actuation_steps;
    EXPECT_NEAR(integrator.delay(), 0.1 * actuation_steps, 0.011) << actuation_steps;
    // Each stamp taken as the state's (not dated): the anchor forgets the commands the held
    // state does not show yet, and most of the acceleration is lost.
    VelocityIntegratorOptions o = options(1, kInf, 0.25);
    o.delay = 0.0;
    VelocityCommandIntegrator undated(o);
    EXPECT_LT(heldVehicleRealises(undated, false, actuation_steps, 0.5), 0.3) << actuation_steps;
    // Not dated but with the delay estimated, the hold is read as a delay of up to P (and one
    // more P of actuation) and made up for as well.
    VelocityCommandIntegrator estimated(options(1, kInf, 0.25));
    EXPECT_NEAR(heldVehicleRealises(estimated, false, actuation_steps, 0.5), 1.0, 0.1)
        << actuation_steps;
  }
}

/// The increments added to a held measurement span at most the history (2 max_delay + 2 T):
/// against a vehicle that cannot exceed 1 m/s the command stays within a h of that bound, and
/// it comes back below the limit soon after the push reverses.
TEST(VelocityCommandIntegrator, NoWindUpAgainstASaturatingVehicleSlowerThanTheController) {
  const double T = 0.01;
  const double a = 2.0;
  VelocityIntegratorOptions o = options(1, kInf, 0.25);
  VelocityCommandIntegrator integrator(o);
  double v = 0.0;
  double latest = 0.0;
  double changed_at = 0.0;
  double largest = 0.0;
  int below_after = -1;
  for (int k = 0; k < 1000; ++k) {
    const double now = k * T;
    if (k % 10 == 0) {
      v = std::min(latest, 1.0);
      changed_at = now;
    }
    ASSERT_TRUE(integrator.measure(vec(v), now, changed_at));
    latest = integrator.step(vec(k < 500 ? a : -a), T, now).velocity(0);
    largest = std::max(largest, latest);
    if (k >= 500 && below_after < 0 && latest < 1.0) {
      below_after = k - 500;
    }
  }
  EXPECT_LE(largest, 1.0 + a * (2.0 * o.max_delay + 3.0 * T) + 1e-9);
  ASSERT_GE(below_after, 0);
  EXPECT_LE(below_after * T, 2.0 * o.max_delay + 3.0 * T);
}

TEST(VelocityCommandIntegrator, RefusesADelayPastItsLimit) {
  VelocityIntegratorOptions o = options(1);
  o.delay = o.max_delay + 0.01;
  EXPECT_EQ(refusedKey(o), "vehicle.velocity.delay");
  o.delay = kNaN;
  EXPECT_EQ(refusedKey(o), "vehicle.velocity.delay");
  o = options(1);
  o.period = 0.0;
  EXPECT_EQ(refusedKey(o), "vehicle.velocity.period");
  o = options(1);
  o.max_delay = 300.0 * o.period;
  EXPECT_EQ(refusedKey(o), "vehicle.velocity.max_delay");
}

/// The unicycle's acceleration command: a_l integrated into ṗ_l, mapped to (v, ω) under limits,
/// and the look-ahead velocity actually commanded, s ṗ_l, fed back: without measurements the
/// integrator stays at what the robot can do instead of winding up.
TEST(VelocityCommandIntegrator, UnicycleLimitsFedBackStopTheWindUp) {
  const UnicycleLookAhead map(0.2, {0.5, 1.0});
  const double reachable = std::hypot(0.5, 0.2 * 1.0);  // the largest ‖ṗ_l‖
  for (bool feed_back : {true, false}) {
    VelocityCommandIntegrator integrator(options(2));
    UnicyclePose pose{0.0, 0.0, 0.3};
    for (int k = 0; k < 1000; ++k) {  // 10 s at 100 Hz
      const VelocityCommand& wanted = integrator.step(vec(1.0, 0.5), 0.01, k * 0.01);
      const UnicycleCommand c = map.command(pose.theta, Eigen::Vector2d(wanted.velocity));
      ASSERT_FALSE(c.refused);
      if (feed_back) {
        integrator.setSent(AxisVector(map.velocity(pose.theta, c.velocity)));
      }
      pose.x += 0.01 * c.velocity.v * std::cos(pose.theta);
      pose.y += 0.01 * c.velocity.v * std::sin(pose.theta);
      pose.theta += 0.01 * c.velocity.omega;
    }
    if (feed_back) {
      EXPECT_LE(integrator.last().velocity.norm(), reachable + 1.2 * 0.01);
    } else {
      EXPECT_NEAR(integrator.last().velocity.norm(), 10.0 * std::hypot(1.0, 0.5), 1e-9);
    }
  }
}

}  // namespace
}  // namespace projection_collision_avoidance
