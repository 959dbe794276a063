/// A convoy follower's parameters (their validation, naming each key) and its slot helpers
/// (doc/math.md, "Convoys on the target's path", (C4)): D = x_t − [r; r'], u_r = r''.

#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <gtest/gtest.h>

#include "projection_collision_avoidance/core/ConvoyReference.hpp"
#include "projection_collision_avoidance/core/ParameterError.hpp"

namespace projection_collision_avoidance {
namespace {

using Vector3 = Eigen::Vector3d;
constexpr double kPeriod = 0.01;
constexpr double kNan = std::numeric_limits<double>::quiet_NaN();

std::string keyOfError(const ConvoyParameters& p) {
  try {
    p.validate("formation.path");
  } catch (const ParameterError& error) {
    EXPECT_EQ(std::string(error.what()).rfind(error.key() + ": ", 0), 0U) << error.what();
    return error.key();
  }
  return "";
}

TEST(ConvoyParameters, ValidateNamesEachBadKey) {
  EXPECT_EQ(keyOfError(ConvoyParameters{}), "");
  constexpr double inf = std::numeric_limits<double>::infinity();
  using P = ConvoyParameters;
  struct Case {
    std::string key;
    double P::*field;
    std::vector<double> bad;
  };
  const std::vector<Case> cases = {
      {"margin_ratio", &P::margin_ratio, {kNan, -0.1, inf}},
      {"gap_ratio", &P::gap_ratio, {kNan, -1.5, 1.3, inf}},  // 1.3 < 1 + margin_ratio
      {"spacing", &P::spacing, {0.0, -0.05, inf, kNan}},
      {"retrace_width", &P::retrace_width, {-0.1, kNan, inf}},
      {"natural_frequency", &P::natural_frequency, {0.0, -2.0, kNan, inf}},
      {"damping", &P::damping, {0.0, -1.0, kNan, inf}},
      {"max_acceleration", &P::max_acceleration, {0.0, -5.0, kNan, inf}},
      {"braking_acceleration", &P::braking_acceleration, {0.0, -4.0, kNan, 5.5}},  // 5.5 > a_max
      {"target_braking", &P::target_braking, {0.0, -5.0, kNan, inf}},
      {"catch_up_speed", &P::catch_up_speed, {0.0, -1.0, kNan, inf}}};
  for (const Case& c : cases) {
    for (const double value : c.bad) {
      P spoilt;
      spoilt.*c.field = value;
      EXPECT_EQ(keyOfError(spoilt), "formation.path." + c.key) << value;
    }
  }
  for (const int capacity : {1, -5, (1 << 20) + 1}) {
    P spoilt;
    spoilt.capacity = capacity;
    EXPECT_EQ(keyOfError(spoilt), "formation.path.capacity") << capacity;
  }
  P crossed;
  crossed.margin_ratio = 0.6;  // gap_ratio 1.5 < 1.6
  EXPECT_EQ(keyOfError(crossed), "formation.path.gap_ratio");
  crossed = P{};
  crossed.max_acceleration = 3.0;  // braking_acceleration 4 > 3
  EXPECT_EQ(keyOfError(crossed), "formation.path.braking_acceleration");
  // The edges are allowed.
  P edges;
  edges.margin_ratio = 0.5;
  edges.gap_ratio = 1.5;
  edges.capacity = 2;
  edges.retrace_width = 0.0;
  edges.braking_acceleration = edges.max_acceleration;
  EXPECT_EQ(keyOfError(edges), "");
  edges.capacity = 1 << 20;
  edges.margin_ratio = 0.0;
  EXPECT_EQ(keyOfError(edges), "");
}

/// (C4): D = x_t − [r; r'], so xi = x_t − x_i − D = [r − p_i; r' − v_i]; u_r = r''.
TEST(ConvoySlot, OffsetAndAccelerationIn2DAnd3D) {
  ConvoySample sample;
  sample.position = Vector3(1.0, -2.0, 0.5);
  sample.velocity = Vector3(0.3, 0.4, -0.1);
  sample.acceleration = Vector3(-0.7, 0.2, 0.9);
  Eigen::Matrix<double, 6, 1> target3, follower3, d3, xi3;
  target3 << 4.0, 1.0, 2.0, 1.0, 0.5, 0.0;
  follower3 << 0.5, -1.5, 0.0, 0.2, 0.1, 0.3;
  convoySlotOffset(target3, 3, sample, &d3);
  xi3 << sample.position - follower3.head<3>(), sample.velocity - follower3.tail<3>();
  EXPECT_LT((target3 - follower3 - d3 - xi3).norm(), 1e-12);
  Eigen::Vector3d u3;
  convoySlotAcceleration(sample, 3, &u3);
  EXPECT_EQ(u3, sample.acceleration);
  // 2-D, in fixed and in run-time sized vectors (z of the sample unused).
  const Eigen::Vector4d target2(4.0, 1.0, 1.0, 0.5), follower2(0.5, -1.5, 0.2, 0.1);
  Eigen::Vector4d d2;
  convoySlotOffset(target2, 2, sample, &d2);
  const Eigen::Vector4d xi2(1.0 - 0.5, -2.0 + 1.5, 0.3 - 0.2, 0.4 - 0.1);
  EXPECT_LT((target2 - follower2 - d2 - xi2).norm(), 1e-12);
  Eigen::VectorXd d_dynamic;
  convoySlotOffset(Eigen::VectorXd(target2), 2, sample, &d_dynamic);
  EXPECT_LT((d_dynamic - d2).norm(), 1e-15);
  Eigen::VectorXd u2(7);  // resized
  convoySlotAcceleration(sample, 2, &u2);
  EXPECT_EQ(u2, Eigen::VectorXd(Eigen::Vector2d(-0.7, 0.2)));
}

/// (C4): a follower that applies u_i = u_r = r'' from xi(0) = 0 (exact double integrator) keeps
/// xi = 0, p_i = r, whatever the target does (here a turning, braking 2-D target).
TEST(ConvoySlot, FollowerApplyingTheKnownInputKeepsXiZero) {
  const ConvoyParameters p;
  ConvoyReference reference(p, kPeriod, 1.0);
  auto target = [](int k) {
    const double t = kPeriod * k;
    const Eigen::Vector2d position(2.0 * std::sin(0.5 * t) + t, 1.0 - std::cos(0.7 * t));
    const Eigen::Vector2d velocity(std::cos(0.5 * t) + 1.0, 0.7 * std::sin(0.7 * t));
    Eigen::Vector4d x;
    x << position, velocity;
    return x;
  };
  const auto lift = [](const Eigen::Vector2d& v) { return Vector3(v.x(), v.y(), 0.0); };
  Eigen::Vector4d x_t = target(0);
  reference.reset(lift(x_t.head<2>()), lift(x_t.tail<2>()), Vector3::UnitX());
  Eigen::Vector4d follower = Eigen::Vector4d::Zero();
  for (int k = 0; k < 3000; ++k) {
    x_t = target(k);
    const ConvoySample s = reference.tick(lift(x_t.head<2>()), lift(x_t.tail<2>()));
    Eigen::Vector4d slot;
    convoySlotOffset(x_t, 2, s, &slot);
    if (k == 0) {
      follower = x_t - slot;  // xi(0) = 0
    }
    const Eigen::Vector4d xi = x_t - follower - slot;
    ASSERT_LT(xi.norm(), 1e-9) << k;
    Eigen::Vector2d u;
    convoySlotAcceleration(s, 2, &u);
    follower.head<2>() += kPeriod * follower.tail<2>() + 0.5 * kPeriod * kPeriod * u;
    follower.tail<2>() += kPeriod * u;
  }
}

}  // namespace
}  // namespace projection_collision_avoidance
