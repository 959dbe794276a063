/// CommandProjection: closed forms, KKT conditions and a sampled brute-force check on random
/// problems, degenerate active sets, and the fallback by priority when the set is empty.

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <limits>
#include <random>
#include <stdexcept>
#include <vector>

#include <Eigen/Core>
#include <Eigen/LU>
#include <Eigen/QR>
#include <Eigen/SVD>
#include <gtest/gtest.h>

#include "projection_collision_avoidance/core/BallConstraint.hpp"
#include "projection_collision_avoidance/core/CommandProjection.hpp"

#include "EigenTestHelpers.hpp"

namespace projection_collision_avoidance {
namespace {

using Eigen::Vector3d;
constexpr double kInf = std::numeric_limits<double>::infinity();

struct HalfSpace {
  Vector3d g;
  double b;
};

HalfSpace h(double gx, double gy, double gz, double b) { return {Vector3d(gx, gy, gz), b}; }

CommandProjection make(int m, const std::vector<HalfSpace>& constraints) {
  CommandProjection projection(m);
  for (const HalfSpace& c : constraints) {
    EXPECT_TRUE(projection.add(c.g, c.b));
  }
  return projection;
}

/// A vector of R^m (entries beyond m zero) with normal entries of standard deviation @p sigma.
Vector3d randomIn(std::mt19937& rng, int m, double sigma) {
  Vector3d x = Vector3d::Zero();
  x.head(m) = testing::randomVector(rng, m, sigma);
  return x;
}

/// Signed distance of @p u inside the half-space (negative: violated).
double inside(const HalfSpace& c, const Vector3d& u) { return (c.g.dot(u) - c.b) / c.g.norm(); }

/// Multipliers x >= 0 (least squares) with matrix x = rhs, both up to 1e-8 s.
bool nonNegativeCombination(const Eigen::MatrixXd& matrix, const Eigen::VectorXd& rhs, double s) {
  const Eigen::VectorXd x = matrix.cols() == 0
                                ? Eigen::VectorXd()
                                : Eigen::VectorXd(matrix.colPivHouseholderQr().solve(rhs));
  return (rhs - matrix * x).norm() <= 1e-8 * s && (x.size() == 0 || x.minCoeff() >= -1e-8 * s);
}

/// Stationarity u_nom - u* = -sum lambda_j g_j + mu u*, with lambda, mu >= 0 on some subset of at
/// most m of the active constraints (the multipliers of the optimum can be carried by one).
bool kktHolds(int m, const std::vector<HalfSpace>& kept, const Vector3d& nominal, double a,
              const Vector3d& u, double s) {
  std::vector<Vector3d> columns;  // unit gradients of the active constraints, signed as above
  for (const HalfSpace& c : kept) {
    if (std::abs(inside(c, u)) <= 1e-7 * s) {
      columns.push_back(-c.g / c.g.norm());
    }
  }
  if (std::isfinite(a) && u.norm() >= a - 1e-7 * s) {
    columns.push_back(u / u.norm());
  }
  const int n = static_cast<int>(columns.size());
  for (int i = 0; i <= n; ++i) {  // subsets {i, j, l}, i <= j <= l, index n for none
    for (int j = i; j <= n; ++j) {
      for (int l = j; l <= n; ++l) {
        Eigen::MatrixXd matrix(m, 0);
        for (const int c : {i, j != i ? j : n, l != j ? l : n}) {  // distinct ones
          if (c < n) {
            matrix.conservativeResize(m, matrix.cols() + 1);
            matrix.rightCols(1) = columns[c].head(m);
          }
        }
        if (matrix.cols() <= m && nonNegativeCombination(matrix, (nominal - u).head(m), s)) {
          return true;
        }
      }
    }
  }
  return false;
}

TEST(CommandProjection, RejectsBadArguments) {
  EXPECT_THROW(CommandProjection(0), std::invalid_argument);
  EXPECT_THROW(CommandProjection(4), std::invalid_argument);
  CommandProjection projection(1);
  EXPECT_FALSE(projection.add(Vector3d(0.0, 1.0, 1.0), 1.0));  // zero in the first m entries
  EXPECT_FALSE(projection.add(Vector3d(NAN, 0.0, 0.0), 1.0));
  EXPECT_FALSE(projection.add(Vector3d(1.0, 0.0, 0.0), kInf));
  EXPECT_TRUE(projection.add(Vector3d(1.0, NAN, 0.0), 1.0));  // entries beyond m are ignored
  while (projection.add(Vector3d(1.0, 0.0, 0.0), -1.0)) {
  }
  EXPECT_EQ(projection.size(), CommandProjection::kMaxConstraints);  // then it was full
  EXPECT_THROW(projection.project(Vector3d(NAN, 0.0, 0.0), 1.0), std::invalid_argument);
  EXPECT_THROW(projection.project(Vector3d::Zero(), 0.0), std::invalid_argument);
  EXPECT_THROW(projection.project(Vector3d::Zero(), NAN), std::invalid_argument);
  projection.clear();
  EXPECT_EQ(projection.project(Vector3d(-5.0, 7.0, 7.0), kInf).command, Vector3d(-5.0, 0, 0));
}

TEST(CommandProjection, FeasibleNominalComesBackBitForBit) {
  std::mt19937 rng(3);
  std::normal_distribution<double> normal;
  for (int trial = 0; trial < 3000; ++trial) {
    const int m = 1 + trial % 3;
    const Vector3d u = randomIn(rng, m, 2.0);
    CommandProjection projection(m);
    for (int j = 0; j < trial % 8; ++j) {
      const Vector3d g = randomIn(rng, m, 3.0);  // u on the plane as computed, or inside:
      projection.add(g, j % 2 == 0 ? g.dot(u) : g.dot(u) - std::abs(normal(rng)));
    }
    const double a = trial % 4 == 0 ? kInf : euclideanNorm(u) * (trial % 4 == 1 ? 1.0 : 1.5);
    const CommandProjectionResult r = projection.project(u, a);
    ASSERT_FALSE(r.changed) << trial;
    ASSERT_EQ(std::memcmp(r.command.data(), u.data(), sizeof(double) * m), 0) << trial;
    ASSERT_EQ(r.dropped, 0);
    ASSERT_EQ(r.ball_active, trial % 4 == 1);
  }
}

/// One half-space without the ball: u_nom + max(0, b - g^T u_nom) / ||g||^2 g; the ball alone:
/// u_nom scaled to ||u|| <= a.
TEST(CommandProjection, SingleHalfSpaceAndBallOnlyClosedForms) {
  std::mt19937 rng(5);
  std::normal_distribution<double> normal;
  for (int trial = 0; trial < 3000; ++trial) {
    const int m = 1 + trial % 3;
    const Vector3d u = randomIn(rng, m, 2.0);
    const Vector3d g = randomIn(rng, m, std::pow(10.0, normal(rng)));
    const double b = 3.0 * normal(rng) * g.norm();
    const Vector3d expected = u + std::max(0.0, b - g.dot(u)) / g.squaredNorm() * g;
    CommandProjectionResult r = make(m, {{g, b}}).project(u, kInf);
    ASSERT_MATRIX_NEAR(r.command, expected, 1e-13 * std::max(u.norm(), std::abs(b) / g.norm()));
    ASSERT_EQ(r.changed, b > g.dot(u));
    ASSERT_EQ(r.active, r.changed ? 1 : 0);
    const double a = 1.0 + trial % 3;
    r = CommandProjection(m).project(u, a);
    ASSERT_MATRIX_NEAR(r.command, u.norm() > a ? Vector3d(u * (a / u.norm())) : u, 1e-15 * a);
    ASSERT_LE(euclideanNorm(r.command), a);
    ASSERT_EQ(r.ball_active, u.norm() > a);
  }
}

/// Random problems: feasible by construction (their planes through or beside a point in the
/// ball) or not (any bounds); the result must be feasible for the kept half-spaces, a KKT point,
/// nearer u_nom than every sampled feasible point around it, and a dropped half-space violated.
void checkRandomProblems(int m, std::uint32_t seed, int trials) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> normal;
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  int ball_active = 0, plane_active[4] = {0, 0, 0, 0}, dropping = 0;
  for (int trial = 0; trial < trials; ++trial) {
    const bool feasible = trial % 10 < 7;
    const double a = trial % 5 == 0 ? kInf : 0.5 + 3.0 * uniform(rng);
    Vector3d anchor = randomIn(rng, m, std::isfinite(a) ? 0.4 * a : 2.0);
    clampNorm(anchor, std::isfinite(a) ? a : kInf);
    std::vector<HalfSpace> constraints;
    const int n =
        trial % 25 == 0 ? CommandProjection::kMaxConstraints : static_cast<int>(uniform(rng) * 9);
    for (int j = 0; j < n; ++j) {
      const Vector3d g = randomIn(rng, m, std::pow(10.0, normal(rng)));
      const double slack = uniform(rng) < 0.3 ? 0.0 : std::abs(normal(rng));  // through anchor
      constraints.push_back(
          {g, feasible ? g.dot(anchor) - slack * g.norm() : 2.0 * normal(rng) * g.norm()});
    }
    const Vector3d nominal = randomIn(rng, m, 3.0);
    const CommandProjectionResult r = make(m, constraints).project(nominal, a);
    const Vector3d u = r.command;
    double s = std::max({nominal.norm(), u.norm(), std::isfinite(a) ? a : 0.0});
    for (const HalfSpace& c : constraints) {
      s = std::max(s, std::abs(c.b) / c.g.norm());  // s of the class comment
    }
    std::vector<HalfSpace> kept;
    for (int j = 0; j < n; ++j) {
      if ((r.dropped_mask >> j) & 1U) {
        ASSERT_LT(inside(constraints[j], u), 1e-9 * s) << "dropped but satisfied, trial " << trial;
      } else {
        ASSERT_GE(inside(constraints[j], u), -1e-9 * s) << "trial " << trial << " j " << j;
        kept.push_back(constraints[j]);
      }
    }
    ASSERT_EQ(__builtin_popcount(r.dropped_mask), r.dropped);
    ASSERT_TRUE(!feasible || r.dropped == 0) << "trial " << trial;
    ASSERT_LE(euclideanNorm(u), a);
    ASSERT_TRUE(u.tail(3 - m).isZero(0.0));
    ASSERT_TRUE(kktHolds(m, kept, nominal, a, u, s))
        << "trial " << trial << " u_nom " << nominal.transpose() << " u* " << u.transpose();
    // Brute force: feasible points sampled at all scales around u* are no nearer u_nom.
    const double distance = (u - nominal).norm();
    for (int k = 0; k < 200; ++k) {
      const Vector3d x = u + randomIn(rng, m, s * std::pow(10.0, -6.0 * uniform(rng)));
      bool ok = !std::isfinite(a) || x.norm() <= a;
      for (const HalfSpace& c : kept) {
        ok = ok && c.g.dot(x) >= c.b;
      }
      ASSERT_TRUE(!ok || (x - nominal).norm() >= distance - 1e-9 * s)
          << "trial " << trial << " sample " << x.transpose() << " beats " << u.transpose();
    }
    // The kept half-spaces intersect the ball: alone, they give the same projection.
    const CommandProjectionResult again = make(m, kept).project(nominal, a);
    ASSERT_EQ(again.dropped, 0);
    ASSERT_MATRIX_NEAR(again.command, u, 1e-9 * s);
    ball_active += r.ball_active ? 1 : 0;
    ++plane_active[std::min(r.active, 3)];
    dropping += r.dropped > 0 ? 1 : 0;
  }
  // The trials exercised every kind of active set (not only the pass-through).
  EXPECT_GT(ball_active, trials / 10);
  EXPECT_GT(plane_active[1], trials / 10);
  EXPECT_GT(plane_active[0], trials / 20);
  EXPECT_GT(plane_active[2], trials / 20);  // in 1-D, planes through one point
  EXPECT_GT(plane_active[3], trials / 20);
  EXPECT_GT(dropping, trials / 20);
}

TEST(CommandProjection, RandomProblems1D) { checkRandomProblems(1, 11, 3000); }
TEST(CommandProjection, RandomProblems2D) { checkRandomProblems(2, 12, 3000); }
TEST(CommandProjection, RandomProblems3D) { checkRandomProblems(3, 13, 3000); }

TEST(CommandProjection, ParallelAndDuplicatedPlanes) {
  // x >= 1, 2x >= 4, -x >= -3 (parallel): from (0, 5) to (2, 5).
  CommandProjectionResult r = make(2, {h(1, 0, 0, 1.0), h(2, 0, 0, 4.0), h(-1, 0, 0, -3.0)})
                                  .project(Vector3d(0, 5, 0), kInf);
  EXPECT_MATRIX_NEAR(r.command, Vector3d(2, 5, 0), 1e-15);
  EXPECT_EQ(r.active, 1);
  // Every plane twice: the corner (1, 1, 1), five equalities; also when it is all of the ball.
  const std::vector<HalfSpace> twice = {h(1, 0, 0, 1.0), h(1, 0, 0, 1.0), h(0, 2, 0, 2.0),
                                        h(0, 1, 0, 1.0), h(0, 0, 1, 1.0)};
  for (const double a : {kInf, 5.0, std::sqrt(3.0)}) {
    r = make(3, twice).project(Vector3d::Zero(), a);
    EXPECT_MATRIX_NEAR(r.command, Vector3d(1, 1, 1), 1e-15) << a;
    EXPECT_EQ(r.active, 5) << a;
    EXPECT_EQ(r.dropped, 0) << a;
    EXPECT_EQ(r.ball_active, a < 2.0) << a;
  }
}

/// Planes through p with normals that positively span R^m (m at angles ~theta and minus their
/// sum) leave only p, but rounded may not meet: nothing is dropped, and u* is within the
/// documented ~kFeasibilityTolerance s / sigma of p (sigma: least singular value of m normals).
TEST(CommandProjection, IllConditionedPlanesThroughOnePoint) {
  std::mt19937 rng(17);
  for (int trial = 0; trial < 3000; ++trial) {
    const int m = 2 + trial % 2;
    const double theta = std::pow(10.0, -1.0 - trial % 9);  // 1e-1 .. 1e-9
    const Vector3d p = randomIn(rng, m, 10.0), common = randomIn(rng, m, 1.0);
    std::vector<HalfSpace> planes;
    Eigen::MatrixXd unit(m, m);
    Vector3d sum = Vector3d::Zero();
    for (int j = 0; j <= m; ++j) {
      const Vector3d g = j < m ? Vector3d(common + randomIn(rng, m, theta)) : Vector3d(-sum);
      sum += g;
      planes.push_back({g, g.dot(p)});
      if (j < m) {
        unit.row(j) = g.head(m).transpose() / g.norm();
      }
    }
    const double sigma = Eigen::JacobiSVD<Eigen::MatrixXd>(unit).singularValues()(m - 1);
    const Vector3d nominal = p + randomIn(rng, m, 5.0);
    const CommandProjectionResult r = make(m, planes).project(nominal, kInf);
    const double s = std::max({nominal.norm(), r.command.norm(), p.norm()});
    ASSERT_EQ(r.dropped, 0) << trial;
    ASSERT_LE((r.command - p).norm(), 100.0 * CommandProjection::kFeasibilityTolerance * s / sigma)
        << trial << " theta " << theta << " sigma " << sigma;
  }
}

TEST(CommandProjection, ThreePlanesThroughOneLine) {
  const std::vector<HalfSpace> fan = {h(1, 0, 0, 0.0), h(0, 1, 0, 0.0), h(1, 1, 0, 0.0)};
  CommandProjectionResult r = make(3, fan).project(Vector3d(-1, -2, 5), kInf);
  EXPECT_MATRIX_NEAR(r.command, Vector3d(0, 0, 5), 1e-15);
  EXPECT_EQ(r.active, 3);
  r = make(3, fan).project(Vector3d(-1, -2, 5), 3.0);  // and the sphere
  EXPECT_MATRIX_NEAR(r.command, Vector3d(0, 0, 3), 1e-15);
  EXPECT_EQ(r.active, 3);
  EXPECT_TRUE(r.ball_active);
  r = make(3, fan).project(Vector3d(-1, 2, 1), kInf);  // one of them active
  EXPECT_MATRIX_NEAR(r.command, Vector3d(0, 2, 1), 1e-15);
  EXPECT_EQ(r.active, 1);
}

TEST(CommandProjection, PlaneTangentToOrCuttingTheBall) {
  for (const int m : {1, 2, 3}) {  // x >= 1 with ||u|| <= 1: the single point (1, 0, 0)
    for (const Vector3d& u : {Vector3d(3, 2, 1), Vector3d(-5, -1, 0.5), Vector3d(0.5, 0, 0)}) {
      // Entries beyond m are ignored.
      const CommandProjectionResult r = make(m, {h(2, 0, 0, 2.0)}).project(u, 1.0);
      EXPECT_MATRIX_NEAR(r.command, Vector3d(1, 0, 0), 1e-12) << m << " " << u.transpose();
      EXPECT_EQ(r.dropped, 0);
      EXPECT_EQ(r.active, 1);
      EXPECT_TRUE(r.ball_active);
    }
  }
  // x >= 1 - 1e-6 cuts a small circle from the sphere: its point nearest u_nom.
  const CommandProjectionResult r =
      make(3, {h(1, 0, 0, 1.0 - 1e-6)}).project(Vector3d(0, 2, 0), 1.0);
  const double x = 1.0 - 1e-6;
  EXPECT_MATRIX_NEAR(r.command, Vector3d(x, std::sqrt(1.0 - x * x), 0), 1e-12);
  EXPECT_EQ(r.dropped, 0);
  EXPECT_EQ(r.active, 1);
}

TEST(CommandProjection, DisjointHalfSpacesDropTheLowerPriority) {
  for (const int m : {1, 2, 3}) {
    const HalfSpace right = h(1, 0, 0, 1.0), left = h(-2, 0, 0, 2.0);  // x >= 1, x <= -1
    CommandProjectionResult r = make(m, {right, left}).project(Vector3d::Zero(), kInf);
    EXPECT_EQ(r.dropped_mask, 2U);
    EXPECT_MATRIX_NEAR(r.command, Vector3d(1, 0, 0), 1e-15);
    r = make(m, {left, right}).project(Vector3d::Zero(), 4.0);
    EXPECT_EQ(r.dropped_mask, 2U);
    EXPECT_MATRIX_NEAR(r.command, Vector3d(-1, 0, 0), 1e-15);
  }
  // x >= 1, y >= 1, x + y <= 1: the last goes; with x + y <= 1 first, y >= 1 goes.
  const HalfSpace x1 = h(1, 0, 0, 1.0), y1 = h(0, 1, 0, 1.0), sum = h(-1, -1, 0, -1.0);
  CommandProjectionResult r = make(2, {x1, y1, sum}).project(Vector3d::Zero(), kInf);
  EXPECT_EQ(r.dropped_mask, 4U);
  EXPECT_MATRIX_NEAR(r.command, Vector3d(1, 1, 0), 1e-15);
  r = make(2, {sum, x1, y1}).project(Vector3d::Zero(), kInf);
  EXPECT_EQ(r.dropped_mask, 4U);
  EXPECT_MATRIX_NEAR(r.command, Vector3d(1, 0, 0), 1e-15);
  EXPECT_EQ(r.active, 2);
}

TEST(CommandProjection, HalfSpacesOutsideTheBallAreDropped) {
  // x >= 1 + 1e-6 just misses ||u|| <= 1: dropped, the ball's projection.
  CommandProjectionResult r = make(3, {h(1, 0, 0, 1.0 + 1e-6)}).project(Vector3d(0, 2, 0), 1.0);
  EXPECT_EQ(r.dropped_mask, 1U);
  EXPECT_MATRIX_NEAR(r.command, Vector3d(0, 1, 0), 1e-15);
  EXPECT_EQ(r.active, 0);
  // x >= 2 misses it; y >= 0.5 is kept: the ball's point nearest (3, 0) with y >= 0.5.
  r = make(2, {h(1, 0, 0, 2.0), h(0, 1, 0, 0.5)}).project(Vector3d(3, 0, 0), 1.0);
  EXPECT_EQ(r.dropped_mask, 1U);
  EXPECT_MATRIX_NEAR(r.command, Vector3d(std::sqrt(0.75), 0.5, 0), 1e-15);
  EXPECT_EQ(r.active, 1);
  EXPECT_TRUE(r.ball_active);
}

/// The nearest feasible point of a 2-D problem by brute force: every candidate of the KKT active
/// sets (u_nom, its radial projection, its foot on each line, each line's points on the circle,
/// each pair of lines' vertex), the feasible one (within 1e-12) nearest u_nom.
Vector3d bruteForce2D(const std::vector<HalfSpace>& constraints, const Vector3d& u, double a_max) {
  std::vector<Vector3d> candidates = {u, u * (a_max / u.norm())};
  for (std::size_t j = 0; j < constraints.size(); ++j) {
    const Vector3d g = constraints[j].g / constraints[j].g.norm();
    const double b = constraints[j].b / constraints[j].g.norm();
    candidates.push_back(u + (b - g.dot(u)) * g);
    const Vector3d tangent(-g.y(), g.x(), 0.0);
    const double r2 = a_max * a_max - b * b;
    if (r2 >= 0.0) {
      candidates.push_back(b * g + std::sqrt(r2) * tangent);
      candidates.push_back(b * g - std::sqrt(r2) * tangent);
    }
    for (std::size_t i = 0; i < j; ++i) {
      Eigen::Matrix2d n;
      n << constraints[i].g.x(), constraints[i].g.y(), constraints[j].g.x(), constraints[j].g.y();
      if (std::abs(n.determinant()) > 1e-9) {
        const Eigen::Vector2d v = n.inverse() * Eigen::Vector2d(constraints[i].b, constraints[j].b);
        candidates.emplace_back(v.x(), v.y(), 0.0);
      }
    }
  }
  Vector3d best = Vector3d::Constant(kInf);
  for (const Vector3d& x : candidates) {
    bool feasible = x.norm() <= a_max + 1e-12;
    for (const HalfSpace& c : constraints) {
      feasible = feasible && inside(c, x) >= -1e-12;
    }
    if (feasible && (x - u).norm() < (best - u).norm()) {
      best = x;
    }
  }
  return best;
}

// crowd_16_gusts.yaml (world.seed=1, a_max 4, neighbours a_b 1, A_n 3, omega 0.5), follower 2 at
// t = 24.47 s: the eight half-spaces (priority order, unit normals) and cf_sim's nominal command
// as passed to project(). One half-space is active, the ball and the others are not (the nearest
// 2.0e-3 away). reference_sim.py's nominal at that tick differs by 1e-4 (its estimate of the
// error has diverged from cf_sim's by rounding) and so does its projection; both are exact.
TEST(CommandProjection, Crowd16Seed1Follower2Tick2447) {
  const std::vector<HalfSpace> constraints = {
      h(0.99998424240853134, -0.0056138164055828136, 0, -0.24473087610661359),
      h(0.50599204899185446, 0.86253814197229839, 0, -0.46853866090088081),
      h(0.99261807964923732, -0.1212821007134212, 0, -1.725285316884805),
      h(0.85345844647933222, 0.52116089658864939, 0, -1.7415222055299937),
      h(0.97719527705853826, 0.21234262524158148, 0, -2.9190460404841869),
      h(0.93611236489037419, 0.35170106667360429, 0, -2.6187969055747775),
      h(0.76174546966653678, 0.64787640753658216, 0, -2.9551768169825832),
      h(0.92661061002951683, -0.37602230968484668, 0, -3.1820344385726318)};
  const CommandProjection projection = make(2, constraints);
  struct Case {
    Vector3d nominal;
    Vector3d expected;  // by NumPy, enumerating every active set
  };
  const Case cases[] = {
      // cf_sim's nominal
      {Vector3d(-3.98238068829686, -0.37502540377983523, 0),
       Vector3d(-0.2469578147939515, -0.39599571243045184, 0)},
      // reference_sim.py's nominal (its projection, with its half-spaces equal to 2e-14)
      {Vector3d(-3.9823715131423865, -0.375122821635817, 0),
       Vector3d(-0.24695836138214433, -0.3960930757095758, 0)},
  };
  for (const Case& c : cases) {
    const CommandProjectionResult r = projection.project(c.nominal, 4.0);
    EXPECT_MATRIX_NEAR(r.command, c.expected, 1e-12);
    EXPECT_MATRIX_NEAR(r.command, bruteForce2D(constraints, c.nominal, 4.0), 1e-13);
    EXPECT_NEAR(inside(constraints[0], r.command), 0.0, 1e-14);
    EXPECT_EQ(r.dropped, 0);
    EXPECT_EQ(r.active, 1);
    EXPECT_FALSE(r.ball_active);
    EXPECT_TRUE(r.changed);
  }
}

}  // namespace
}  // namespace projection_collision_avoidance
