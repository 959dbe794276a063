/// The control barrier function safety filter (doc/math.md, "A control barrier function
/// filter", (B1)-(B3)): the barrier's half-space against its derivatives taken numerically, the
/// closed form against the QP, the barrier kept in a closed loop, the infeasible case, the
/// parameters' validation.

#include <cmath>
#include <limits>
#include <random>

#include <Eigen/Core>
#include <gtest/gtest.h>

#include "projection_collision_avoidance/core/BallConstraint.hpp"
#include "projection_collision_avoidance/core/ParameterError.hpp"
#include "projection_collision_avoidance/core/SafetyFilter.hpp"

namespace projection_collision_avoidance {
namespace {

using Vector3 = Eigen::Vector3d;
constexpr double kInfinity = std::numeric_limits<double>::infinity();

Vector3 randomVector(std::mt19937* random, double scale, int k = 3) {
  std::normal_distribution<double> normal(0.0, scale);
  Vector3 v = Vector3::Zero();
  for (int i = 0; i < k; ++i) {
    v(i) = normal(*random);
  }
  return v;
}

/// h(t) = ||p(t)||^2 − rho^2 along p(t) = p + v t + (u_i − a_j) t^2 / 2.
double barrierAt(const Vector3& p, const Vector3& v, const Vector3& relative_acceleration,
                 double rho, double t) {
  return (p + t * v + 0.5 * t * t * relative_acceleration).squaredNorm() - rho * rho;
}

TEST(SafetyFilter, TheHalfSpaceIsTheExponentialBarriersConditionHalved) {
  // g^T u − b = (h'' + 2 lambda h' + lambda^2 h) / 2 for any command u, with h' and h'' taken
  // numerically from h along the motion under u.
  std::mt19937 random(7);
  for (int trial = 0; trial < 200; ++trial) {
    const Vector3 p = randomVector(&random, 5.0);
    const Vector3 v = randomVector(&random, 2.0);
    const Vector3 a_j = randomVector(&random, 1.0);
    const Vector3 u = randomVector(&random, 3.0);
    const double rho = 1.0 + trial % 4;
    const double lambda = 0.5 + 0.1 * (trial % 10);
    const BarrierConstraint c = exponentialBarrier(p, v, a_j, rho, lambda);
    // Five-point stencils: exact (up to rounding) for h, a quartic in t.
    const double dt = 1e-2;
    const auto at = [&](double t) { return barrierAt(p, v, u - a_j, rho, t); };
    const double h = at(0.0);
    const double h_dot = (at(-2 * dt) - 8.0 * at(-dt) + 8.0 * at(dt) - at(2 * dt)) / (12.0 * dt);
    const double h_ddot =
        (-at(-2 * dt) + 16.0 * at(-dt) - 30.0 * h + 16.0 * at(dt) - at(2 * dt)) / (12.0 * dt * dt);
    EXPECT_NEAR(c.barrier, h, 1e-12 * (1.0 + std::abs(h)));
    EXPECT_NEAR(c.barrier_rate, h_dot, 1e-9 * (1.0 + std::abs(h)));
    const double condition = h_ddot + 2.0 * lambda * h_dot + lambda * lambda * h;
    EXPECT_NEAR(c.normal.dot(u) - c.bound, 0.5 * condition, 1e-7 * (1.0 + std::abs(h))) << trial;
    EXPECT_EQ(c.normal, p);
  }
}

TEST(SafetyFilter, TheClosedFormIsTheQpOfOneBarrierWithoutALimit) {
  std::mt19937 random(11);
  for (int k = 1; k <= 3; ++k) {
    SafetyFilter filter(k);
    for (int trial = 0; trial < 300; ++trial) {
      const Vector3 u_nom = randomVector(&random, 3.0, k);
      const Vector3 g = randomVector(&random, 4.0, k);
      const double b = std::normal_distribution<double>(0.0, 10.0)(random);
      const Vector3 closed = singleBarrierCommand(u_nom, g, b);
      filter.clear();
      BarrierConstraint c;
      c.normal = g;
      c.bound = b;
      ASSERT_TRUE(filter.add(c));
      const SafetyFilterResult r = filter.filter(u_nom, kInfinity);
      EXPECT_LT((r.command - closed).norm(), 1e-9 * (1.0 + std::abs(b) / g.norm())) << k;
      EXPECT_GE(g.dot(closed), b - 1e-9 * (std::abs(b) + g.norm() * u_nom.norm()));
      EXPECT_FALSE(r.infeasible);
      if (g.dot(u_nom) >= b) {
        EXPECT_EQ(closed, u_nom);  // a feasible nominal command passes unchanged
        EXPECT_FALSE(r.changed);
        EXPECT_EQ(r.active, -1);
      } else {
        EXPECT_NEAR(g.dot(closed), b, 1e-9 * (std::abs(b) + g.norm() * u_nom.norm()));
        EXPECT_EQ(r.active, 0);  // the barrier holds with equality
      }
    }
  }
}

TEST(SafetyFilter, AZeroNormalOrANonFiniteBarrierIsNotAdded) {
  SafetyFilter filter(2);
  BarrierConstraint c;
  EXPECT_FALSE(filter.add(c));  // g = 0: the agents coincide
  c.normal << 1.0, 0.0, 0.0;
  c.bound = std::numeric_limits<double>::quiet_NaN();
  EXPECT_FALSE(filter.add(c));
  EXPECT_EQ(filter.size(), 0);
  EXPECT_EQ(singleBarrierCommand(Vector3(1.0, 2.0, 0.0), Vector3::Zero(), 5.0),
            Vector3(1.0, 2.0, 0.0));
}

/// A double integrator driven at a standing agent at the origin, the command filtered at each
/// step of @p period (s) and held over it (@p filtered false: the nominal command acts); returns
/// the smallest distance (m) and counts the steps that changed the command.
double closestApproach(double rho, double lambda, double limit, double period, bool filtered,
                       int* changed, int* infeasible) {
  SafetyFilter filter(2);
  Vector3 p(6.0, 0.2, 0.0);
  Vector3 v(-1.0, 0.0, 0.0);
  double closest = p.norm();
  for (int k = 0; k < static_cast<int>(20.0 / period); ++k) {
    const Vector3 nominal = -2.0 * (p - Vector3(-3.0 * rho, 0.0, 0.0)) - 2.5 * v;  // through it
    filter.clear();
    filter.add(exponentialBarrier(p, v, Vector3::Zero(), rho, lambda));
    const SafetyFilterResult r = filter.filter(nominal, limit);
    *changed += r.changed ? 1 : 0;
    *infeasible += r.infeasible ? 1 : 0;
    const Vector3 u = filtered ? r.command : nominal;
    p += period * v + 0.5 * period * period * u;
    v += period * u;
    closest = std::min(closest, p.norm());
  }
  return closest;
}

TEST(SafetyFilter, TheBarrierKeepsTheAgentOutOfThePerimeter) {
  // Nominal: to a point behind the agent, straight through it. Started with h >= 0 and
  // h' + lambda h >= 0, the filtered loop stays out of rho (within the sampling's O(T) error).
  const double rho = 2.0;
  int changed = 0;
  int infeasible = 0;
  ASSERT_LT(closestApproach(rho, 1.0, kInfinity, 1e-3, false, &changed, &infeasible), 0.5 * rho);
  for (const double lambda : {0.5, 1.0, 3.0}) {
    changed = 0;
    const double closest =
        closestApproach(rho, lambda, kInfinity, 1e-3, true, &changed, &infeasible);
    EXPECT_GE(closest, rho * (1.0 - 1e-3)) << lambda;
    EXPECT_GT(changed, 100) << lambda;  // the filter acted
  }
  EXPECT_EQ(infeasible, 0);
}

TEST(SafetyFilter, TooFastForTheLimitIsInfeasibleAndBrakesAtTheLimit) {
  // Closing at 6 m/s from 3 m, lambda = 3 1/s, a_max = 2 m/s^2: no command within the limit
  // meets (B2).
  SafetyFilter filter(2);
  const Vector3 p(3.0, 0.0, 0.0);
  const Vector3 v(-6.0, 0.0, 0.0);
  const BarrierConstraint c = exponentialBarrier(p, v, Vector3::Zero(), 2.0, 3.0);
  ASSERT_GT(c.bound, 2.0 * c.normal.norm());
  ASSERT_TRUE(filter.add(c));
  const SafetyFilterResult r = filter.filter(Vector3(-1.0, 0.5, 0.0), 2.0);
  EXPECT_TRUE(r.infeasible);
  EXPECT_EQ(r.dropped, 1);
  EXPECT_LT((r.command - Vector3(2.0, 0.0, 0.0)).norm(), 1e-12);  // a_max along g_0
  EXPECT_TRUE(r.limit_active);
  // A second, less urgent barrier that does not fit with the first is left out instead.
  SafetyFilter two(2);
  BarrierConstraint first;
  first.normal << 1.0, 0.0, 0.0;
  first.bound = 1.0;  // u_x >= 1
  BarrierConstraint second;
  second.normal << -1.0, 0.0, 0.0;
  second.bound = 0.5;  // u_x <= −0.5
  ASSERT_TRUE(two.add(first));
  ASSERT_TRUE(two.add(second));
  const SafetyFilterResult s = two.filter(Vector3(0.0, 0.3, 0.0), 3.0);
  EXPECT_TRUE(s.infeasible);
  EXPECT_EQ(s.dropped, 1);
  EXPECT_EQ(s.active, 0);
  EXPECT_LT((s.command - Vector3(1.0, 0.3, 0.0)).norm(), 1e-12);
}

TEST(SafetyFilter, BestEffortKeepsTheLimitAtEveryScaleOfTheBarrier) {
  // g_0 = s (1, 2) with b_0 = 3 s, out of reach of a_max = 1 at any scale s: the best effort is
  // (1, 2) / sqrt(5), also where ||g_0|| overflows or its square underflows.
  const Vector3 expected = Vector3(1.0, 2.0, 0.0) / std::sqrt(5.0);
  for (const double s : {1e-170, 1e-160, 1e-100, 1e-3, 1.0, 3.0, 1e100, 1e160, 1e300}) {
    SafetyFilter filter(2);
    BarrierConstraint c;
    c.normal << s, 2.0 * s, 0.0;
    c.bound = 3.0 * s;
    ASSERT_TRUE(filter.add(c)) << s;
    const SafetyFilterResult r = filter.filter(Vector3::Zero(), 1.0);
    EXPECT_TRUE(r.infeasible) << s;
    EXPECT_TRUE(r.command.allFinite()) << s;
    EXPECT_LE(euclideanNorm(r.command), 1.0) << s;
    EXPECT_LT((r.command - expected).norm(), 1e-15) << s;
    EXPECT_TRUE(r.changed) << s;
  }
  // A nominal command that is already the best effort, to the QP's tolerance, is not moved (nor
  // counted as moved).
  SafetyFilter line(1);
  BarrierConstraint c;
  c.normal << 2.0, 0.0, 0.0;
  c.bound = 5.0;  // u >= 2.5, out of reach of a_max = 1
  ASSERT_TRUE(line.add(c));
  const SafetyFilterResult r = line.filter(Vector3(1.0, 0.0, 0.0), 1.0);
  EXPECT_TRUE(r.infeasible);
  EXPECT_FALSE(r.changed);
  EXPECT_EQ(r.command, Vector3(1.0, 0.0, 0.0));
  const Vector3 below(1.0 - 1e-14, 0.0, 0.0);  // an ulp or so short of a_max: kept as it is
  EXPECT_EQ(line.filter(below, 1.0).command, below);
  EXPECT_TRUE(line.filter(Vector3(0.5, 0.0, 0.0), 1.0).changed);
}

TEST(SafetyFilterParameters, ValidateNamesTheKey) {
  SafetyFilterParameters p;
  EXPECT_NO_THROW(p.validate("controller.safety_filter"));
  for (const double bad : {0.0, -1.0, kInfinity, std::numeric_limits<double>::quiet_NaN()}) {
    p.rate = bad;
    try {
      p.validate("controller.safety_filter");
      ADD_FAILURE() << bad;
    } catch (const ParameterError& error) {
      EXPECT_EQ(error.key(), "controller.safety_filter.rate");
    }
  }
}

}  // namespace
}  // namespace projection_collision_avoidance
