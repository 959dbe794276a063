/// A convoy follower's reference (doc/math.md, "Convoys on the target's path", (C2)-(C5)): the
/// goal, the reference r with its bounded acceleration and the stopping-distance barrier. The
/// parameters' validation and the slot helpers (C4): test_convoy_slot.cpp.

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <random>
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

/// The target at one tick: position and velocity (m, m/s).
struct TargetState {
  Vector3 position;
  Vector3 velocity;
};

/// c_min = (1 + m / 2) ||d|| and h of (C5) at @p sample, the target as given.
double floorChord(const ConvoyParameters& p, double d) { return (1.0 + 0.5 * p.margin_ratio) * d; }
double barrier(const ConvoyParameters& p, double d, const ConvoySample& sample,
               const TargetState& target) {
  const Vector3 n = (target.position - sample.position).normalized();
  const double v_r = std::max(0.0, n.dot(sample.velocity));
  const double v_t = std::max(0.0, n.dot(target.velocity));
  return sample.chord - floorChord(p, d) - v_r * v_r / (2.0 * p.braking_acceleration) +
         v_t * v_t / (2.0 * p.target_braking);
}

/// Runs @p ticks ticks of a reference reset on @p motion(0), checking at every tick what (C2),
/// (C3) and (C5) promise whatever the target does: r'' held over T and r, r' integrated exactly
/// with it (r and r' continuous, ||r'_{k+1} − r'_k|| <= a_max T), ||r''|| <= a_max, the goal at
/// least (1 + m) ||d|| from the target and never faster along the path than the target's progress
/// plus catch_up_speed, the sample finite, and the component of r'' along n within the bound of
/// (C5) (a stricter bound is allowed: the doc's is what keeps h >= 0).
std::vector<ConvoySample> run(const ConvoyParameters& p, double d, int ticks,
                              const std::function<TargetState(int)>& motion,
                              const Vector3& direction = Vector3::UnitX()) {
  ConvoyReference reference(p, kPeriod, d);
  const TargetState start = motion(0);
  reference.reset(start.position, start.velocity, direction);
  std::vector<ConvoySample> samples;
  for (int k = 0; k < ticks; ++k) {
    const TargetState target = motion(k);
    const ConvoySample s = reference.tick(target.position, target.velocity);
    EXPECT_TRUE(s.position.allFinite() && s.velocity.allFinite() && s.acceleration.allFinite() &&
                s.goal.allFinite() && std::isfinite(s.progress) && std::isfinite(s.goal_arc) &&
                std::isfinite(s.chord))
        << k;
    EXPECT_LE(s.acceleration.norm(), p.max_acceleration * (1.0 + 1e-12)) << k;
    const bool known = target.position.allFinite() && target.velocity.allFinite();
    if (target.position.allFinite()) {
      EXPECT_GE((target.position - s.goal).norm(), reference.goalChord() * (1.0 - 1e-12)) << k;
    }
    if (!samples.empty()) {
      const ConvoySample& last = samples.back();
      const Vector3 r =
          last.position + kPeriod * last.velocity + 0.5 * kPeriod * kPeriod * last.acceleration;
      EXPECT_LT((s.position - r).norm(), 1e-9) << k;
      EXPECT_LT((s.velocity - (last.velocity + kPeriod * last.acceleration)).norm(), 1e-9) << k;
      EXPECT_LE((s.velocity - last.velocity).norm(), p.max_acceleration * kPeriod + 1e-12) << k;
      EXPECT_LE(s.goal_arc, last.goal_arc + std::max(0.0, s.progress - last.progress) +
                                p.catch_up_speed * kPeriod + 1e-9)
          << k;
      // (C5) from the sample's own r, r' and the target.
      const double omega = p.natural_frequency;
      if (known) {
        EXPECT_NEAR(s.chord, (target.position - s.position).norm(), 1e-12) << k;
        const Vector3 n = (target.position - s.position) / s.chord;
        const double v_r = n.dot(s.velocity);
        const double v_t = n.dot(target.velocity);
        const double bound = std::max(
            -p.max_acceleration,
            p.braking_acceleration * (omega * barrier(p, d, s, target) + std::min(0.0, v_t) - v_r) /
                std::max(std::max(v_r, 0.0), p.braking_acceleration * kPeriod));
        EXPECT_LE(n.dot(s.acceleration), bound + 1e-9) << k;
      } else {
        EXPECT_FALSE(s.braking) << k;
      }
    }
    samples.push_back(s);
  }
  return samples;
}

/// Straight along the unit @p u from @p origin at @p speed.
std::function<TargetState(int)> straight(const Vector3& origin, const Vector3& u, double speed) {
  return [=](int k) { return TargetState{origin + speed * kPeriod * k * u, speed * u}; };
}

/// Along x at @p speed, braking at @p deceleration from tick @p start to rest (the braking held
/// over each period, exactly), @p ticks ticks.
std::vector<TargetState> brakingTarget(double speed, double deceleration, int start, int ticks) {
  std::vector<TargetState> states;
  double x = 0.0;
  double v = speed;
  for (int k = 0; k < ticks; ++k) {
    states.push_back({Vector3(x, 0.0, 0.0), Vector3(v, 0.0, 0.0)});
    const double dt = k >= start ? std::min(kPeriod, v / deceleration) : kPeriod;
    x += v * dt - (k >= start ? 0.5 * deceleration * dt * dt : 0.0);
    v = k >= start ? std::max(0.0, v - deceleration * kPeriod) : v;
  }
  return states;
}

std::function<TargetState(int)> replay(const std::vector<TargetState>& states) {
  return [&states](int k) { return states[static_cast<std::size_t>(k)]; };
}

TEST(ConvoyReference, ResetStartsAtTheGoalWithTheTargetsVelocityAlongTheDirection) {
  ConvoyParameters p;
  ConvoyReference reference(p, kPeriod, 2.0);
  EXPECT_DOUBLE_EQ(reference.gap(), 3.0);
  EXPECT_DOUBLE_EQ(reference.goalChord(), 2.8);
  const Vector3 u = Vector3(1.0, 2.0, 2.0) / 3.0;
  reference.reset(Vector3(1.0, -1.0, 0.5), Vector3(0.3, 0.9, 0.0), u);
  const ConvoySample s = reference.tick(Vector3(1.0, -1.0, 0.5), Vector3(0.3, 0.9, 0.0));
  EXPECT_LT((s.position - (Vector3(1.0, -1.0, 0.5) - 3.0 * u)).norm(), 1e-12);
  EXPECT_LT((s.velocity - u.dot(Vector3(0.3, 0.9, 0.0)) * u).norm(), 1e-12);
  EXPECT_LT((s.goal - s.position).norm(), 1e-12);
  EXPECT_DOUBLE_EQ(s.goal_arc, -3.0);
  EXPECT_DOUBLE_EQ(s.chord, 3.0);
}

/// At a speed v where the barrier's cruising chord c_min + v^2 / (2 a_b) − v^2 / (2 A) + v / omega
/// is below the gap (0.5 m/s, ||d|| = 1), r converges to the point gap behind the target on its
/// path and r' to the target's velocity, from a reference started at rest.
TEST(ConvoyReference, FollowsTheGapBehindAStraightTargetAtLowSpeed) {
  const ConvoyParameters p;
  const Vector3 u = Vector3(1.0, 2.0, -2.0) / 3.0;
  auto target = straight(Vector3(2.0, 0.0, 1.0), u, 0.5);
  auto at_rest = [&](int k) {  // reset with the target's velocity unknown (0): r' = 0
    return k == 0 ? TargetState{target(0).position, Vector3::Zero()} : target(k);
  };
  const std::vector<ConvoySample> samples = run(p, 1.0, 3000, at_rest, u);
  const ConvoySample& s = samples.back();
  const TargetState t = target(2999);
  EXPECT_LT((s.position - (t.position - 1.5 * u)).norm(), 1e-4);
  EXPECT_LT((s.velocity - t.velocity).norm(), 1e-4);
  EXPECT_NEAR(s.progress, 0.5 * kPeriod * 2999, 1e-9);
  EXPECT_NEAR(s.goal_arc, s.progress - 1.5, 1e-9);
  EXPECT_FALSE(s.braking);
}

/// Faster (2 m/s) the barrier (C5) holds r where n . r'' = 0 is its bound: omega h = v_r = v, so
/// the chord settles at c_min + v^2 / (2 a_b) − v^2 / (2 A) + v / omega (1.2 + 0.5 − 0.4 + 1 m),
/// beyond the goal's gap, with r' the target's velocity and the barrier acting.
TEST(ConvoyReference, CruisesAtTheBarriersChordBehindAFastStraightTarget) {
  const ConvoyParameters p;
  const Vector3 u = Vector3(0.6, 0.8, 0.0);
  auto target = straight(Vector3::Zero(), u, 2.0);
  const std::vector<ConvoySample> samples = run(p, 1.0, 3000, target, u);
  const ConvoySample& s = samples.back();
  const TargetState t = target(2999);
  EXPECT_NEAR(s.chord, 1.2 + 0.5 - 0.4 + 1.0, 1e-4);
  EXPECT_LT((s.position - (t.position - s.chord * u)).norm(), 1e-4);  // on the path
  EXPECT_LT((s.velocity - t.velocity).norm(), 1e-4);
  EXPECT_TRUE(s.braking);
}

/// The guarantee of (C5): from h >= 0, a target that brakes to rest at no more than A (straight
/// ahead: v_t >= 0) keeps c >= c_min. Reset at speed v with the chord the gap, so that h starts
/// at 0.3 − v^2 / 40 >= 0, and braking at A or less from the first tick or later. At the edge,
/// h(0) = 0 (3.46 m/s), up to the discretisation's error of order T (a quarter of v T).
TEST(ConvoyReference, BarrierKeepsTheChordWhenTheTargetBrakesWithinTargetBraking) {
  const ConvoyParameters p;
  const double edge = std::sqrt(0.3 / (1.0 / 8.0 - 1.0 / 10.0)) * (1.0 - 1e-9);
  for (const double speed : {1.0, 2.0, 3.0, 3.4, edge}) {
    const double tolerance = speed == edge ? 0.25 * speed * kPeriod : 0.0;
    for (const double deceleration : {5.0, 3.0, 1.0}) {
      for (const int start : {0, 5, 100, 1000}) {
        const std::vector<TargetState> target =
            brakingTarget(speed, deceleration, start, start + 800);
        const std::vector<ConvoySample> samples = run(p, 1.0, start + 800, replay(target));
        EXPECT_GE(barrier(p, 1.0, samples.front(), target.front()), 0.0);
        for (const ConvoySample& s : samples) {
          ASSERT_GE(s.chord, floorChord(p, 1.0) - tolerance)
              << speed << " m/s braking at " << deceleration << " from tick " << start;
        }
      }
    }
  }
}

/// The barrier acts where the pull (C3) alone would close the chord below c_min: a reference that
/// only pulls toward the goal (the same (C3), no (C5)) overshoots it when the target brakes at A
/// from 3 m/s; the reference brakes (the flag set) and keeps c >= c_min.
TEST(ConvoyReference, BrakingFlagMarksWhereThePullAloneWouldOvershoot) {
  const ConvoyParameters p;
  const std::vector<TargetState> target = brakingTarget(3.0, 5.0, 0, 600);
  const std::vector<ConvoySample> samples = run(p, 1.0, 600, replay(target));
  // The pull alone (C3) toward the same goals.
  Vector3 r = samples.front().position;
  Vector3 r_dot = samples.front().velocity;
  double pull_lowest = 1e9;
  int braking = 0;
  for (std::size_t k = 0; k < samples.size(); ++k) {
    const Vector3 q_dot =
        k == 0 ? r_dot : Vector3((samples[k].goal - samples[k - 1].goal) / kPeriod);
    Vector3 a = 4.0 * (samples[k].goal - r) + 4.0 * (q_dot - r_dot);
    a *= std::min(1.0, p.max_acceleration / a.norm());
    pull_lowest = std::min(pull_lowest, (target[k].position - r).norm());
    r += kPeriod * r_dot + 0.5 * kPeriod * kPeriod * a;
    r_dot += kPeriod * a;
    EXPECT_GE(samples[k].chord, floorChord(p, 1.0)) << k;
    braking += samples[k].braking ? 1 : 0;
  }
  EXPECT_LT(pull_lowest, floorChord(p, 1.0));
  EXPECT_GT(braking, 0);
}

/// A target turning on circles (radius 1.5 to 10 m, ||d|| = 1) at up to 3 m/s, after 4 m straight,
/// and braking at A on the circle: it never drives toward the reference (v_t >= 0), so the chord
/// keeps c_min.
TEST(ConvoyReference, TurningTargetKeepsTheChord) {
  const ConvoyParameters p;
  for (const double radius : {1.5, 3.0, 10.0}) {
    for (const double speed : {1.0, 2.0, 3.0}) {
      for (const int brake : {100000, 800}) {  // the tick it brakes at 5 m/s^2 from
        std::vector<TargetState> target;
        double arc = 0.0;
        double v = speed;
        for (int k = 0; k < 2000; ++k) {
          const double theta = std::max(0.0, arc - 4.0) / radius;
          const Vector3 e(std::cos(theta), std::sin(theta), 0.0);
          target.push_back(
              {Vector3(std::min(arc, 4.0) + radius * e.y(), radius * (1.0 - e.x()), 0.0), v * e});
          const double next = k >= brake ? std::max(0.0, v - 5.0 * kPeriod) : v;
          arc += 0.5 * (v + next) * kPeriod;
          v = next;
        }
        for (const ConvoySample& s : run(p, 1.0, 2000, replay(target))) {
          ASSERT_GE(s.chord, floorChord(p, 1.0)) << radius << " m, " << speed << " m/s";
        }
      }
    }
  }
}

/// Any target (random jumps, reversals, turns on the spot, stops, its position or velocity lost
/// (NaN) for a tick): the tick-by-tick promises checked by run() hold.
TEST(ConvoyReference, BoundsHoldForAnyTargetMotion) {
  ConvoyParameters p;
  p.max_acceleration = 3.0;
  p.braking_acceleration = 2.5;
  std::mt19937 random(11);
  std::normal_distribution<double> normal(0.0, 1.0);
  std::uniform_int_distribution<int> kind(0, 99);
  Vector3 position = Vector3::Zero();
  Vector3 velocity = Vector3::UnitX();
  int last = 0;
  auto target = [&](int k) {
    for (; last < k; ++last) {
      const int event = kind(random);
      if (event == 0) {
        velocity = -velocity;  // reverses
      } else if (event == 1) {
        position += Vector3(normal(random), normal(random), 0.0);  // a jump
      } else if (event < 4) {
        velocity = Vector3(normal(random), normal(random), 0.3 * normal(random));
      }
      position += kPeriod * velocity;
    }
    TargetState state{position, velocity};
    if (k > 0 && k % 97 == 0) {
      (k % 2 == 0 ? state.position : state.velocity).y() = kNan;
    }
    return state;
  };
  run(p, 1.3, 20000, target, Vector3(0.0, 1.0, 0.0));
}

/// The target's position lost (NaN) for 0.2 s while it drives straight at 0.5 m/s: the samples
/// stay finite (checked by run()), the goal holds its arc instead of jumping back along the path,
/// r slows toward the held goal without stopping or reversing, and once the target is back r
/// converges to the gap behind it again.
TEST(ConvoyReference, LostTargetPositionDoesNotThrowTheGoalBack) {
  const ConvoyParameters p;
  auto clean = straight(Vector3::Zero(), Vector3::UnitX(), 0.5);
  auto noisy = [&](int k) {
    TargetState t = clean(k);
    if (k >= 1000 && k < 1020) {
      t.position.x() = kNan;
    }
    return t;
  };
  const std::vector<ConvoySample> samples = run(p, 1.0, 2000, noisy);
  double lowest_speed = 1e9;
  double largest_step_back = 0.0;
  for (int k = 995; k < 1100; ++k) {
    lowest_speed = std::min(lowest_speed, samples[k].velocity.x());
    largest_step_back = std::max(largest_step_back, samples[k - 1].goal_arc - samples[k].goal_arc);
  }
  EXPECT_LE(largest_step_back, 1e-9) << "the goal jumped back along the path";
  EXPECT_GT(lowest_speed, 0.0) << "r stopped or reversed";
  EXPECT_LT((samples.back().position - (clean(1999).position - 1.5 * Vector3::UnitX())).norm(),
            1e-3);
}

TEST(ConvoyReference, AnIntervalAdvancesByItsTimeAndNoTimeRepeatsTheSample) {
  ConvoyParameters p;
  const auto target = [](int k) {
    return TargetState{Vector3(10.0 + 1.5 * kPeriod * k, 0.5, 0.0), Vector3(1.5, 0.0, 0.0)};
  };
  ConvoyReference by_period(p, kPeriod, 5.0);
  ConvoyReference by_interval(p, kPeriod, 5.0);
  by_period.reset(target(0).position, target(0).velocity, Vector3::UnitX());
  by_interval.reset(target(0).position, target(0).velocity, Vector3::UnitX());
  ConvoySample before = by_interval.tick(target(0).position, target(0).velocity, 0.03);
  EXPECT_EQ(before.position, by_period.tick(target(0).position, target(0).velocity).position)
      << "the first tick after reset samples r(0) whatever the interval";
  for (int k = 1; k < 300; ++k) {  // tick() is tick(.., T), bit for bit
    const ConvoySample a = by_period.tick(target(k).position, target(k).velocity);
    const ConvoySample b = by_interval.tick(target(k).position, target(k).velocity, kPeriod);
    ASSERT_EQ(a.position, b.position) << k;
    ASSERT_EQ(a.velocity, b.velocity) << k;
    ASSERT_EQ(a.acceleration, b.acceleration) << k;
    before = b;
  }
  // No time (0, less, NaN): the sample before, whatever the target now is.
  for (const double none : {0.0, -kPeriod, kNan}) {
    const ConvoySample same = by_interval.tick(Vector3(50.0, 3.0, 0.0), Vector3::Zero(), none);
    EXPECT_EQ(same.position, before.position);
    EXPECT_EQ(same.goal, before.goal);
    EXPECT_EQ(same.acceleration, before.acceleration);
  }
  // An interval of 3 T: r and r' advance over it with the r'' before held.
  const double dt = 3.0 * kPeriod;
  const ConvoySample after = by_interval.tick(target(302).position, target(302).velocity, dt);
  const Vector3 position =
      before.position + dt * before.velocity + 0.5 * dt * dt * before.acceleration;
  EXPECT_LT((after.position - position).norm(), 1e-12);
  EXPECT_LT((after.velocity - (before.velocity + dt * before.acceleration)).norm(), 1e-12);
}

}  // namespace
}  // namespace projection_collision_avoidance
