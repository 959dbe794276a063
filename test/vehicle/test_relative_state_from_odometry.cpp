/// RelativeStateFromOdometry and the rotations it uses: body twists rotated into the world frame
/// in 2-D and 3-D against hand-computed cases, the alignment of two stamps by constant velocity,
/// the skew refused one step past its limit, and refused samples (non-finite values, quaternions
/// far from unit length, overflow) with their verdicts.

#include <cmath>
#include <limits>
#include <string>

#include <gtest/gtest.h>

#include "projection_collision_avoidance/core/ParameterError.hpp"
#include "projection_collision_avoidance/vehicle/RelativeStateFromOdometry.hpp"
#include "projection_collision_avoidance/vehicle/Rotation.hpp"
#include "projection_collision_avoidance/vehicle/UnicycleLookAhead.hpp"

#include "EigenTestHelpers.hpp"

namespace projection_collision_avoidance {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

Eigen::Quaterniond yaw(double angle) {
  return Eigen::Quaterniond(Eigen::AngleAxisd(angle, Eigen::Vector3d::UnitZ()));
}

Eigen::Quaterniond roll(double angle) {
  return Eigen::Quaterniond(Eigen::AngleAxisd(angle, Eigen::Vector3d::UnitX()));
}

OdometrySample sample(double stamp, const Eigen::Vector3d& position,
                      const Eigen::Quaterniond& orientation, const Eigen::Vector3d& velocity) {
  OdometrySample s;
  s.stamp = stamp;
  s.position = position;
  s.orientation = orientation;
  s.linear_velocity = velocity;
  return s;
}

OdometryAlignmentOptions options(int axes, double max_skew = 0.05) {
  OdometryAlignmentOptions o;
  o.axes = axes;
  o.max_skew = max_skew;
  return o;
}

std::string refusedKey(const OdometryAlignmentOptions& o) {
  try {
    RelativeStateFromOdometry adapter(o);
  } catch (const ParameterError& e) {
    return e.key();
  }
  return "";
}

TEST(Rotation, BodyToWorldHandComputed) {
  // Yaw 90°: the body's x axis points along the world's y axis.
  EXPECT_MATRIX_NEAR(bodyToWorld(yaw(kPi / 2), Eigen::Vector3d(1, 0, 0)), Eigen::Vector3d(0, 1, 0),
                     1e-14);
  EXPECT_MATRIX_NEAR(bodyToWorld(yaw(kPi / 2), Eigen::Vector3d(0, 1, 0)), Eigen::Vector3d(-1, 0, 0),
                     1e-14);
  // q = Rz(90°) Rx(90°): body x → world y, body y → world z, body z → world x.
  const Eigen::Quaterniond q = yaw(kPi / 2) * roll(kPi / 2);
  EXPECT_MATRIX_NEAR(bodyToWorld(q, Eigen::Vector3d(1, 2, 3)), Eigen::Vector3d(3, 1, 2), 1e-14);
  EXPECT_MATRIX_NEAR(worldToBody(q, Eigen::Vector3d(3, 1, 2)), Eigen::Vector3d(1, 2, 3), 1e-14);
  EXPECT_NEAR(yawOf(yaw(2.5)), 2.5, 1e-14);
  EXPECT_NEAR(yawOf(q), kPi / 2, 1e-14);
}

TEST(Rotation, NormalisesWithinTheToleranceAndRefusesBeyond) {
  Eigen::Quaterniond q(yaw(0.3).coeffs() * 1.005);
  EXPECT_EQ(normaliseQuaternion(q, 1e-2), QuaternionStatus::kUnit);
  EXPECT_NEAR(q.norm(), 1.0, 1e-14);
  EXPECT_MATRIX_NEAR(q.coeffs(), yaw(0.3).coeffs(), 1e-14);
  Eigen::Quaterniond far(yaw(0.3).coeffs() * 1.02);
  const Eigen::Vector4d before = far.coeffs();
  EXPECT_EQ(normaliseQuaternion(far, 1e-2), QuaternionStatus::kNotUnit);
  EXPECT_EQ(far.coeffs(), before);      // left unchanged
  Eigen::Quaterniond zero(0, 0, 0, 0);  // an orientation that was never filled in
  EXPECT_EQ(normaliseQuaternion(zero, 1e-2), QuaternionStatus::kNotUnit);
  EXPECT_EQ(normaliseQuaternion(zero, kInf), QuaternionStatus::kNotUnit);
  Eigen::Quaterniond nan(kNaN, 0, 0, 1);
  EXPECT_EQ(normaliseQuaternion(nan, 1e-2), QuaternionStatus::kNotFinite);
  EXPECT_STREQ(toString(QuaternionStatus::kNotUnit), "not_unit");
}

TEST(RelativeStateFromOdometry, RefusesUnusableOptions) {
  OdometryAlignmentOptions o = options(0);
  EXPECT_EQ(refusedKey(o), "vehicle.odometry.axes");
  o = options(4);
  EXPECT_EQ(refusedKey(o), "vehicle.odometry.axes");
  EXPECT_EQ(refusedKey(options(1)), "");
  o = options(2, -0.1);
  EXPECT_EQ(refusedKey(o), "vehicle.odometry.max_skew");
  o = options(3, kNaN);
  EXPECT_EQ(refusedKey(o), "vehicle.odometry.max_skew");
  o = options(2);
  o.quaternion_tolerance = kInf;
  EXPECT_EQ(refusedKey(o), "vehicle.odometry.quaternion_tolerance");
  o = options(2);
  o.target_point.x() = kNaN;
  EXPECT_EQ(refusedKey(o), "vehicle.odometry.target_point");
  EXPECT_EQ(refusedKey(options(3, 0.0)), "");
}

TEST(RelativeStateFromOdometry, PlanarBodyTwistsRotatedByTheirYaw) {
  const RelativeStateFromOdometry adapter(options(2));
  // The follower at (1, 2) heading +y at 1 m/s forward; the target at (4, 6) heading +x at
  // 2 m/s forward and 0.5 m/s to its left (world +y).
  const OdometrySample self =
      sample(5.0, Eigen::Vector3d(1, 2, 0.3), yaw(kPi / 2), Eigen::Vector3d(1, 0, 0));
  const OdometrySample target =
      sample(5.0, Eigen::Vector3d(4, 6, -0.2), yaw(0.0), Eigen::Vector3d(2, 0.5, 0));
  const RelativeOdometryResult r = adapter.compute(self, target);
  ASSERT_TRUE(r.accepted()) << toString(r.verdict);
  ASSERT_EQ(r.state.size(), 4);
  EXPECT_MATRIX_NEAR(r.state, Eigen::Vector4d(3, 4, 2, -0.5), 1e-14);
  EXPECT_EQ(r.stamp, 5.0);
  EXPECT_EQ(r.skew, 0.0);
  EXPECT_FALSE(r.self_extrapolated);
  EXPECT_FALSE(r.target_extrapolated);
}

TEST(RelativeStateFromOdometry, SpatialBodyTwistsRotatedByTheirOrientation) {
  const RelativeStateFromOdometry adapter(options(3));
  // Target: q = Rz(90°) Rx(90°), body twist (1, 2, 3) → world (3, 1, 2); the follower: yaw
  // 180°, body twist (1, 0, 0.5) → world (−1, 0, 0.5).
  const Eigen::Quaterniond q = yaw(kPi / 2) * roll(kPi / 2);
  const OdometrySample target = sample(1.0, Eigen::Vector3d(1, 1, 3), q, Eigen::Vector3d(1, 2, 3));
  const OdometrySample self =
      sample(1.0, Eigen::Vector3d(0, 0, 1), yaw(kPi), Eigen::Vector3d(1, 0, 0.5));
  const RelativeOdometryResult r = adapter.compute(self, target);
  ASSERT_TRUE(r.accepted()) << toString(r.verdict);
  Eigen::Matrix<double, 6, 1> expected;
  expected << 1, 1, 2, 4, 1, 1.5;
  EXPECT_MATRIX_NEAR(r.state, expected, 1e-14);

  // The same twists given in the world frame are not rotated.
  OdometryAlignmentOptions world = options(3);
  world.twist_frame = TwistFrame::kWorld;
  const RelativeOdometryResult w = RelativeStateFromOdometry(world).compute(self, target);
  ASSERT_TRUE(w.accepted());
  expected.tail<3>() << 0, 2, 2.5;
  EXPECT_MATRIX_NEAR(w.state, expected, 1e-14);
}

TEST(RelativeStateFromOdometry, OlderSampleExtrapolatedAtConstantVelocity) {
  const RelativeStateFromOdometry adapter(options(2, 0.1));
  const OdometrySample self =
      sample(10.0, Eigen::Vector3d(0, 0, 0), yaw(0.0), Eigen::Vector3d(2, 0, 0));
  const OdometrySample target = sample(10.0625, Eigen::Vector3d(3, 1, 0), yaw(kPi / 2),
                                       Eigen::Vector3d(1, 0, 0));  // world (0, 1)
  RelativeOdometryResult r = adapter.compute(self, target);
  ASSERT_TRUE(r.accepted());
  EXPECT_TRUE(r.self_extrapolated);
  EXPECT_FALSE(r.target_extrapolated);
  EXPECT_EQ(r.stamp, 10.0625);
  EXPECT_EQ(r.skew, 0.0625);
  // The follower moved 2 m/s · 0.0625 s = 0.125 m along x meanwhile.
  EXPECT_MATRIX_NEAR(r.state, Eigen::Vector4d(2.875, 1, -2, 1), 1e-14);

  // The other way round: the target's sample is the older one.
  const OdometrySample late_self =
      sample(10.125, Eigen::Vector3d(0, 0, 0), yaw(0.0), Eigen::Vector3d(2, 0, 0));
  r = adapter.compute(late_self, target);
  ASSERT_TRUE(r.accepted());
  EXPECT_TRUE(r.target_extrapolated);
  EXPECT_EQ(r.stamp, 10.125);
  EXPECT_MATRIX_NEAR(r.state, Eigen::Vector4d(3, 1.0625, -2, 1), 1e-14);
}

TEST(RelativeStateFromOdometry, SkewAcceptedAtItsLimitAndRefusedOnePast) {
  const RelativeStateFromOdometry adapter(options(2, 0.25));
  const OdometrySample self =
      sample(10.0, Eigen::Vector3d::Zero(), yaw(0.0), Eigen::Vector3d::Zero());
  OdometrySample target =
      sample(10.25, Eigen::Vector3d(1, 0, 0), yaw(0.0), Eigen::Vector3d::Zero());
  EXPECT_TRUE(adapter.compute(self, target).accepted());
  EXPECT_TRUE(adapter.compute(target, self).accepted());
  target.stamp = std::nextafter(10.25, kInf);
  for (const RelativeOdometryResult& r :
       {adapter.compute(self, target), adapter.compute(target, self)}) {
    EXPECT_FALSE(r.accepted());
    EXPECT_EQ(r.verdict, OdometryVerdict::kSkewTooLarge);
    EXPECT_STREQ(toString(r.verdict), "skew_too_large");
    EXPECT_GT(r.skew, 0.25);
    EXPECT_TRUE(r.state.isZero(0.0));
  }
  // Stamps too far apart to subtract are refused too.
  target.stamp = std::numeric_limits<double>::max();
  OdometrySample early = self;
  early.stamp = -std::numeric_limits<double>::max();
  EXPECT_EQ(adapter.compute(early, target).verdict, OdometryVerdict::kSkewTooLarge);
}

TEST(RelativeStateFromOdometry, QuaternionsNormalisedWithinTheToleranceRefusedBeyond) {
  const RelativeStateFromOdometry adapter(options(2));
  const OdometrySample self =
      sample(2.0, Eigen::Vector3d(0, 0, 0), yaw(0.4), Eigen::Vector3d(1, 0, 0));
  const OdometrySample target =
      sample(2.0, Eigen::Vector3d(2, 0, 0), yaw(-0.8), Eigen::Vector3d(1.5, 0, 0));
  const RelativeOdometryResult unit = adapter.compute(self, target);
  ASSERT_TRUE(unit.accepted());

  OdometrySample scaled = self;
  scaled.orientation.coeffs() *= 0.995;
  const RelativeOdometryResult normalised = adapter.compute(scaled, target);
  ASSERT_TRUE(normalised.accepted());
  EXPECT_MATRIX_NEAR(normalised.state, unit.state, 1e-14);

  scaled.orientation.coeffs() = self.orientation.coeffs() * 1.0101;
  EXPECT_EQ(adapter.compute(scaled, target).verdict, OdometryVerdict::kSelfQuaternionNotUnit);
  OdometrySample zero = target;
  zero.orientation = Eigen::Quaterniond(0, 0, 0, 0);
  EXPECT_EQ(adapter.compute(self, zero).verdict, OdometryVerdict::kTargetQuaternionNotUnit);
}

TEST(RelativeStateFromOdometry, NonFiniteValuesRefusedNeverThrown) {
  const RelativeStateFromOdometry adapter(options(3));
  const OdometrySample good =
      sample(1.0, Eigen::Vector3d(1, 2, 3), yaw(0.1), Eigen::Vector3d(0.1, 0, 0));
  OdometrySample bad = good;
  bad.position.y() = kNaN;
  EXPECT_EQ(adapter.compute(bad, good).verdict, OdometryVerdict::kSelfNotFinite);
  EXPECT_EQ(adapter.compute(good, bad).verdict, OdometryVerdict::kTargetNotFinite);
  bad = good;
  bad.stamp = kInf;
  EXPECT_EQ(adapter.compute(bad, good).verdict, OdometryVerdict::kSelfNotFinite);
  bad = good;
  bad.linear_velocity.z() = -kInf;
  EXPECT_EQ(adapter.compute(good, bad).verdict, OdometryVerdict::kTargetNotFinite);
  bad = good;
  bad.orientation.coeffs()(3) = kNaN;
  EXPECT_EQ(adapter.compute(bad, good).verdict, OdometryVerdict::kSelfNotFinite);
  // The angular velocity is used only for a controlled point away from the body's origin.
  bad = good;
  bad.angular_velocity.z() = kNaN;
  EXPECT_TRUE(adapter.compute(bad, good).accepted());
  OdometryAlignmentOptions ahead = options(3);
  ahead.self_point = Eigen::Vector3d(0.3, 0, 0);
  EXPECT_EQ(RelativeStateFromOdometry(ahead).compute(bad, good).verdict,
            OdometryVerdict::kSelfNotFinite);
  // Finite samples whose difference overflows.
  OdometrySample far = good;
  far.position.x() = std::numeric_limits<double>::max();
  OdometrySample other_side = good;
  other_side.position.x() = -std::numeric_limits<double>::max();
  const RelativeOdometryResult r = adapter.compute(other_side, far);
  EXPECT_EQ(r.verdict, OdometryVerdict::kOverflow);
  EXPECT_TRUE(r.state.isZero(0.0));
}

TEST(PoseFrame, ReadsItsTwoNamesAndRefusesOthersNamingTheKey) {
  EXPECT_EQ(poseFrameOf("header"), PoseFrame::kHeader);
  EXPECT_EQ(poseFrameOf("world"), PoseFrame::kWorld);
  EXPECT_STREQ(toString(PoseFrame::kHeader), "header");
  EXPECT_STREQ(toString(PoseFrame::kWorld), "world");
  for (const char* bad : {"", "body", "World", "map", "header "}) {
    try {
      poseFrameOf(bad);
      ADD_FAILURE() << "accepted \"" << bad << "\"";
    } catch (const ParameterError& e) {
      EXPECT_EQ(e.key(), "~odometry/pose_frame");
    }
  }
}

TEST(OdometryOriginState, BodyTwistTurnedIntoThePoseFrameHeaderTwistAsItIs) {
  // Yaw 90°: the body's x axis is the world's y axis.
  const OdometrySample s =
      sample(1.0, Eigen::Vector3d(1, 2, 3), yaw(kPi / 2), Eigen::Vector3d(0.4, 0.1, 0.5));
  PlanarOrSpatialState x;
  ASSERT_EQ(originState(s, TwistFrame::kBody, 1e-2, 2, &x), OdometryVerdict::kAccepted);
  Eigen::Vector4d planar;
  planar << 1, 2, -0.1, 0.4;
  EXPECT_MATRIX_NEAR(x, planar, 1e-15);
  ASSERT_EQ(originState(s, TwistFrame::kWorld, 1e-2, 2, &x), OdometryVerdict::kAccepted);
  planar.tail<2>() << 0.4, 0.1;
  EXPECT_MATRIX_NEAR(x, planar, 0.0);
  ASSERT_EQ(originState(s, TwistFrame::kBody, 1e-2, 3, &x), OdometryVerdict::kAccepted);
  Eigen::Matrix<double, 6, 1> spatial;
  spatial << 1, 2, 3, -0.1, 0.4, 0.5;
  EXPECT_MATRIX_NEAR(x, spatial, 1e-15);
  ASSERT_EQ(originState(s, TwistFrame::kBody, 1e-2, 1, &x), OdometryVerdict::kAccepted);
  EXPECT_MATRIX_NEAR(x, Eigen::Vector2d(1, -0.1), 1e-15);
  // The orientation is the same as RelativeStateFromOdometry's (within its tolerance).
  OdometrySample scaled = s;
  scaled.orientation.coeffs() *= 0.995;
  ASSERT_EQ(originState(scaled, TwistFrame::kBody, 1e-2, 2, &x), OdometryVerdict::kAccepted);
  EXPECT_MATRIX_NEAR(x.tail(2), Eigen::Vector2d(-0.1, 0.4), 1e-15);
}

TEST(OdometryOriginState, RefusesWhatItCannotTurnNeverThrows) {
  OdometrySample s = sample(1.0, Eigen::Vector3d(1, 2, 0), yaw(0.3), Eigen::Vector3d(1, 0, 0));
  PlanarOrSpatialState x;
  // The orientation matters only to a body twist.
  s.orientation = Eigen::Quaterniond(0, 0, 0, 0);
  EXPECT_EQ(originState(s, TwistFrame::kBody, 1e-2, 2, &x),
            OdometryVerdict::kSelfQuaternionNotUnit);
  EXPECT_EQ(originState(s, TwistFrame::kWorld, 1e-2, 2, &x), OdometryVerdict::kAccepted);
  s.orientation.coeffs()(0) = kNaN;
  EXPECT_EQ(originState(s, TwistFrame::kBody, 1e-2, 2, &x), OdometryVerdict::kSelfNotFinite);
  EXPECT_EQ(originState(s, TwistFrame::kWorld, 1e-2, 2, &x), OdometryVerdict::kAccepted);
  s = sample(1.0, Eigen::Vector3d(1, kInf, 0), yaw(0.3), Eigen::Vector3d(1, 0, 0));
  EXPECT_EQ(originState(s, TwistFrame::kWorld, 1e-2, 2, &x), OdometryVerdict::kSelfNotFinite);
  s = sample(1.0, Eigen::Vector3d(1, 2, 0), yaw(0.3), Eigen::Vector3d(kNaN, 0, 0));
  EXPECT_EQ(originState(s, TwistFrame::kBody, 1e-2, 2, &x), OdometryVerdict::kSelfNotFinite);
  // Finite components that overflow once turned by 45°.
  const double big = std::numeric_limits<double>::max();
  s = sample(1.0, Eigen::Vector3d(0, 0, 0), yaw(kPi / 4), Eigen::Vector3d(big, -big, 0));
  EXPECT_EQ(originState(s, TwistFrame::kBody, 1e-2, 2, &x), OdometryVerdict::kOverflow);
}

TEST(RelativeStateFromOdometry, LookAheadPointsAsTheUnicycleMapGivesThem) {
  // Two unicycles controlled at look-ahead points 0.3 m and 0.5 m ahead: the relative state of
  // the body-fixed points equals the difference of UnicycleLookAhead's states.
  const UnicycleLookAhead own(0.3);
  const UnicycleLookAhead other(0.5);
  const UnicyclePose self_pose{1.0, -2.0, 0.7};
  const UnicycleVelocity self_body{0.8, -0.4};
  const UnicyclePose target_pose{3.0, 1.0, -2.1};
  const UnicycleVelocity target_body{1.1, 0.9};

  OdometryAlignmentOptions o = options(2);
  o.self_point = Eigen::Vector3d(0.3, 0, 0);
  o.target_point = Eigen::Vector3d(0.5, 0, 0);
  OdometrySample self = sample(4.0, Eigen::Vector3d(self_pose.x, self_pose.y, 0),
                               yaw(self_pose.theta), Eigen::Vector3d(self_body.v, 0, 0));
  self.angular_velocity.z() = self_body.omega;
  OdometrySample target = sample(4.0, Eigen::Vector3d(target_pose.x, target_pose.y, 0),
                                 yaw(target_pose.theta), Eigen::Vector3d(target_body.v, 0, 0));
  target.angular_velocity.z() = target_body.omega;
  const RelativeOdometryResult r = RelativeStateFromOdometry(o).compute(self, target);
  ASSERT_TRUE(r.accepted());
  EXPECT_MATRIX_NEAR(
      r.state, other.state(target_pose, target_body) - own.state(self_pose, self_body), 1e-14);
}

}  // namespace
}  // namespace projection_collision_avoidance
