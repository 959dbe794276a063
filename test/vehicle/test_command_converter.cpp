/// CommandConverter: the acceleration passed through, the velocity anchored on the own odometry
/// (its body-frame twist rotated into the world), the base frame, the unicycle's (v, ω) with its
/// limits fed back, each kind's stop (braking acceleration), and the stop without a heading.

#include <cmath>
#include <limits>
#include <string>

#include <gtest/gtest.h>

#include "projection_collision_avoidance/core/ParameterError.hpp"
#include "projection_collision_avoidance/vehicle/CommandConverter.hpp"

namespace projection_collision_avoidance {
namespace {

constexpr double kPeriod = 0.01;

CommandConverterOptions options(bool unicycle = false, bool base_frame = false) {
  CommandConverterOptions o;
  o.axes = 2;
  o.period = kPeriod;
  o.max_odometry_age = 0.1;
  o.unicycle = unicycle;
  o.velocity_in_base_frame = base_frame;
  o.look_ahead = 0.2;
  o.stop_deceleration = 1.0;
  return o;
}

/// Own odometry at @p stamp: heading @p yaw (rad), body-frame velocity (@p vx, @p vy), yaw
/// rate @p omega.
OdometrySample own(double stamp, double yaw, double vx, double vy = 0.0, double omega = 0.0) {
  OdometrySample s;
  s.stamp = stamp;
  s.orientation = Eigen::Quaterniond(Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()));
  s.linear_velocity = Eigen::Vector3d(vx, vy, 0.0);
  s.angular_velocity = Eigen::Vector3d(0.0, 0.0, omega);
  return s;
}

Eigen::VectorXd accel(double x, double y) { return Eigen::Vector2d(x, y); }

TEST(CommandConverter, TheVelocityLeadsTheMeasuredOneInTheWorldFrame) {
  CommandConverter converter(options());
  // Heading 90 deg, 1 m/s forward in the body frame: (0, 1) m/s in the world.
  ASSERT_TRUE(converter.observe(own(10.0, M_PI / 2, 1.0)));
  const ConvertedCommand& c = converter.convert(accel(0.5, 0.0), 10.0);
  EXPECT_EQ(c.anchor, VelocityAnchor::kMeasured);
  EXPECT_NEAR(c.velocity.x(), 0.5 * kPeriod, 1e-12);  // lead a h, h = T without a lag
  EXPECT_NEAR(c.velocity.y(), 1.0, 1e-12);
  EXPECT_NEAR(c.acceleration.x(), 0.5, 0.0);
  EXPECT_TRUE(c.heading_known);
  EXPECT_FALSE(c.stop);
}

TEST(CommandConverter, InTheBaseFrameTheVelocityTurnsWithTheHeading) {
  CommandConverter converter(options(false, true));
  ASSERT_TRUE(converter.observe(own(10.0, M_PI / 2, 1.0)));
  const ConvertedCommand& c = converter.convert(accel(0.5, 0.0), 10.0);
  // World (0.005, 1) seen from a body yawed by 90 deg: (1, -0.005).
  EXPECT_NEAR(c.velocity.x(), 1.0, 1e-12);
  EXPECT_NEAR(c.velocity.y(), -0.5 * kPeriod, 1e-12);
}

TEST(CommandConverter, WithoutAFreshHeadingBaseFrameAndUnicycleSendTheStop) {
  for (const bool unicycle : {false, true}) {
    CommandConverter converter(options(unicycle, !unicycle));
    ASSERT_TRUE(converter.observe(own(10.0, 0.0, 1.0)));
    const ConvertedCommand& c = converter.convert(accel(1.0, 0.0), 10.2);  // 0.2 s > 0.1 s
    EXPECT_FALSE(c.heading_known) << unicycle;
    EXPECT_EQ(c.velocity.norm(), 0.0) << unicycle;
    EXPECT_EQ(c.unicycle.velocity.v, 0.0) << unicycle;
    EXPECT_EQ(c.unicycle.velocity.omega, 0.0) << unicycle;
  }
  // In the world frame the velocity integrates on from the previous command instead.
  CommandConverter world(options());
  ASSERT_TRUE(world.observe(own(10.0, 0.0, 1.0)));
  world.convert(accel(1.0, 0.0), 10.0);
  const ConvertedCommand& c = world.convert(accel(1.0, 0.0), 10.2);
  EXPECT_TRUE(c.heading_known);
  EXPECT_EQ(c.anchor, VelocityAnchor::kPreviousCommand);
  EXPECT_NEAR(c.velocity.x(), 1.0 + 2.0 * kPeriod, 1e-12);
}

TEST(CommandConverter, AUnicycleTurnsTowardASidewaysAcceleration) {
  CommandConverter converter(options(true));
  ASSERT_TRUE(converter.observe(own(10.0, 0.0, 0.0)));  // at rest, facing +x
  const ConvertedCommand& ahead = converter.convert(accel(1.0, 0.0), 10.0);
  EXPECT_NEAR(ahead.unicycle.velocity.v, kPeriod, 1e-12);
  EXPECT_NEAR(ahead.unicycle.velocity.omega, 0.0, 1e-12);
  // The robot did as it was told: 0.01 m/s ahead.
  ASSERT_TRUE(converter.observe(own(10.01, 0.0, kPeriod)));
  const ConvertedCommand& left = converter.convert(accel(0.0, 1.0), 10.01);
  // The look-ahead point 0.2 m ahead keeps on ahead and moves left at 0.01 m/s as well:
  // omega = 0.01 / 0.2.
  EXPECT_NEAR(left.unicycle.velocity.v, kPeriod, 1e-12);
  EXPECT_NEAR(left.unicycle.velocity.omega, kPeriod / 0.2, 1e-12);
}

TEST(CommandConverter, TheUnicycleLimitsAreFedBackToTheIntegrator) {
  CommandConverterOptions o = options(true);
  o.unicycle_limits.max_yaw_rate = 0.01;
  CommandConverter converter(o);
  ASSERT_TRUE(converter.observe(own(10.0, 0.0, 0.0)));
  const ConvertedCommand& c = converter.convert(accel(0.0, 1.0), 10.0);
  EXPECT_TRUE(c.unicycle.yaw_rate_limited);
  EXPECT_NEAR(c.unicycle.velocity.omega, 0.01, 1e-12);
  EXPECT_NEAR(c.unicycle.scale, 0.2, 1e-12);  // 0.05 rad/s wanted
  // No odometry any more: the heading is unknown, so the stop (not a wound-up command).
  const ConvertedCommand& later = converter.convert(accel(0.0, 1.0), 10.5);
  EXPECT_FALSE(later.heading_known);
  EXPECT_EQ(later.unicycle.velocity.omega, 0.0);
}

TEST(CommandConverter, TheStopBrakesAndZeroesTheVelocities) {
  CommandConverter converter(options());
  ASSERT_TRUE(converter.observe(own(10.0, M_PI, 2.0)));  // facing -x at 2 m/s: world (-2, 0)
  converter.convert(accel(1.0, 0.0), 10.0);
  const ConvertedCommand& fast = converter.stop(10.0);
  EXPECT_TRUE(fast.stop);
  EXPECT_EQ(fast.velocity.norm(), 0.0);
  EXPECT_NEAR(fast.acceleration.x(), 1.0, 1e-12);  // against the motion, at stop_deceleration
  EXPECT_NEAR(fast.acceleration.y(), 0.0, 1e-12);
  ASSERT_TRUE(converter.observe(own(10.01, 0.0, 0.004)));
  const ConvertedCommand& slow = converter.stop(10.01);
  EXPECT_NEAR(slow.acceleration.x(), -0.004 / kPeriod, 1e-12);  // to rest within one period
  const ConvertedCommand& blind = converter.stop(11.0);         // no fresh odometry
  EXPECT_EQ(blind.acceleration.norm(), 0.0);
  // After a stop the velocity integrates from rest again.
  const ConvertedCommand& again = converter.convert(accel(1.0, 0.0), 11.0);
  EXPECT_EQ(again.anchor, VelocityAnchor::kPreviousCommand);
  EXPECT_NEAR(again.velocity.x(), kPeriod, 1e-12);
}

/// A vehicle whose state changes less often than its odometry is published repeats the same
/// state with new stamps: the state is dated by the first of them.
TEST(CommandConverter, ARepeatedStateIsDatedByItsFirstStamp) {
  CommandConverter converter(options());
  ASSERT_TRUE(converter.observe(own(1.0, 0.3, 0.5)));
  EXPECT_EQ(converter.stateChangedAt(), 1.0);
  ASSERT_TRUE(converter.observe(own(1.05, 0.3, 0.5)));
  EXPECT_EQ(converter.stateChangedAt(), 1.0);
  ASSERT_TRUE(converter.observe(own(1.1, 0.3, 0.6)));  // a new velocity
  EXPECT_EQ(converter.stateChangedAt(), 1.1);
  OdometrySample moved = own(1.2, 0.3, 0.6);
  moved.position.x() = 1e-3;
  ASSERT_TRUE(converter.observe(moved));
  EXPECT_EQ(converter.stateChangedAt(), 1.2);
  moved.stamp = 1.15;  // the same state stamped earlier: dated by that stamp
  ASSERT_TRUE(converter.observe(moved));
  EXPECT_EQ(converter.stateChangedAt(), 1.15);
}

TEST(CommandConverter, ANonFiniteConversionGivesTheStopInstead) {
  // A world-frame odometry twist of (1.5e308, 1.5e308) m/s, finite, turned into a base frame
  // yawed by 45 deg: 2.1e308 overflows to inf.
  CommandConverterOptions o = options(false, true);
  o.odometry_twist_frame = TwistFrame::kWorld;
  CommandConverter converter(o);
  ASSERT_TRUE(converter.observe(own(10.0, M_PI / 4, 1.5e308, 1.5e308)));
  const ConvertedCommand& c = converter.convert(accel(0.0, 0.0), 10.0);
  EXPECT_TRUE(isFinite(c));
  EXPECT_TRUE(c.replaced_non_finite);
  EXPECT_TRUE(c.stop);
  EXPECT_EQ(c.velocity, Eigen::Vector3d::Zero());
  // An infinite acceleration (the adapter turns a huge finite one by tf): the stop, braking
  // from the measured 1 m/s.
  CommandConverter plain(options());
  ASSERT_TRUE(plain.observe(own(10.0, 0.0, 1.0)));
  const ConvertedCommand& d =
      plain.convert(accel(std::numeric_limits<double>::infinity(), 0.0), 10.0);
  EXPECT_TRUE(isFinite(d));
  EXPECT_TRUE(d.replaced_non_finite);
  EXPECT_NEAR(d.acceleration.x(), -1.0, 1e-12);
  // The next finite command is converted again.
  EXPECT_FALSE(plain.convert(accel(0.5, 0.0), 10.01).replaced_non_finite);
}

TEST(CommandConverter, AnOdometrySpikeGivesNoCommandBeyondTheLimits) {
  // One odometry of 1000 m/s anchors the velocity command: it stays within the limits.
  for (const bool base_frame : {false, true}) {
    CommandConverterOptions o = options(false, base_frame);
    o.velocity.max_speed = 4.0;
    CommandConverter converter(o);
    ASSERT_TRUE(converter.observe(own(10.0, 0.3, 1000.0, -20.0)));
    const ConvertedCommand& c = converter.convert(accel(1.0, 0.0), 10.0);
    EXPECT_TRUE(c.speed_limited);
    EXPECT_LE(c.velocity.norm(), 4.0 * (1.0 + 1e-15)) << "base frame " << base_frame;
  }
  CommandConverterOptions o = options(true);
  o.unicycle_limits.max_speed = 4.0;
  o.unicycle_limits.max_yaw_rate = 3.0;
  o.velocity.max_speed = 4.0;
  CommandConverter unicycle(o);
  ASSERT_TRUE(unicycle.observe(own(10.0, 0.3, 1000.0, 0.0, 500.0)));
  const ConvertedCommand& c = unicycle.convert(accel(0.0, 2.0), 10.0);
  EXPECT_LE(std::abs(c.unicycle.velocity.v), 4.0);
  EXPECT_LE(std::abs(c.unicycle.velocity.omega), 3.0);
  EXPECT_TRUE(isFinite(c));
}

TEST(CommandConverter, RefusesUnusableOptionsAndOdometry) {
  const auto refused = [](const CommandConverterOptions& o) {
    try {
      CommandConverter converter(o);
    } catch (const ParameterError& e) {
      return std::string(e.key());
    }
    return std::string();
  };
  CommandConverterOptions o = options(true);
  o.axes = 3;
  EXPECT_EQ(refused(o), "vehicle.command.unicycle");
  o = options();
  o.period = 0.0;
  EXPECT_EQ(refused(o), "vehicle.command.period");
  o = options();
  o.stop_deceleration = std::nan("");
  EXPECT_EQ(refused(o), "vehicle.command.stop_deceleration");
  EXPECT_EQ(refused(options()), "");

  CommandConverter converter(options());
  OdometrySample bad = own(10.0, 0.0, 1.0);
  bad.linear_velocity.x() = std::nan("");
  EXPECT_FALSE(converter.observe(bad));
  bad = own(10.0, 0.0, 1.0);
  bad.orientation.coeffs() *= 2.0;
  EXPECT_FALSE(converter.observe(bad));
}

}  // namespace
}  // namespace projection_collision_avoidance
