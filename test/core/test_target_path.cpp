/// The convoy's path (doc/math.md, "Convoys on the target's path", (C1) and walkBack of (C2)):
/// recording, arc length, retracing, the virtual road, the ring and at(). walkBack():
/// test_target_path_walk_back.cpp.

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include <Eigen/Core>
#include <gtest/gtest.h>

#include "projection_collision_avoidance/core/TargetPath.hpp"

#include "TargetPathDrives.hpp"

namespace projection_collision_avoidance {
namespace {

constexpr double kPi = 3.141592653589793;
// Steps and spacings that are powers of two: positions and arcs on a straight line are exact.
constexpr double kStep = 1.0 / 16.0;
constexpr double kSpacing = 1.0 / 8.0;

/// ||P(a) − P(b)|| <= |a − b| on [from, to] (P is parametrised by its arc length) and P has no
/// jump: checked on a fine grid.
void expectArcLengthParametrised(const TargetPath& path, double from, double to) {
  const double h = 1e-3;
  Eigen::Vector3d previous = path.at(from);
  for (double sigma = from + h; sigma <= to; sigma += h) {
    const Eigen::Vector3d current = path.at(sigma);
    ASSERT_TRUE(current.allFinite()) << sigma;
    ASSERT_LE((current - previous).norm(), h * (1.0 + 1e-9)) << sigma;
    previous = current;
  }
}

TEST(TargetPath, RecordsPointsSpacingApartAndProgressIsTheDistanceDriven) {
  TargetPath path(64, kSpacing, 0.5);
  path.reset(Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitX());
  EXPECT_EQ(path.size(), 1);
  EXPECT_EQ(path.progress(), 0.0);
  for (int k = 1; k <= 40; ++k) {  // 2.5 m along x, 16 steps a metre
    path.record(Eigen::Vector3d(k * kStep, 0.0, 0.0));
    EXPECT_EQ(path.size(), 1 + k / 2) << k;  // a point every second step: kSpacing apart
    EXPECT_EQ(path.progress(), k * kStep) << k;
  }
  for (int j = 0; j <= 20; ++j) {  // the recorded points, exactly
    EXPECT_EQ(path.at(j * kSpacing), Eigen::Vector3d(j * kSpacing, 0.0, 0.0)) << j;
  }
  // A step shorter than the spacing is not recorded; the target still counts in the progress.
  path.record(Eigen::Vector3d(2.5, 0.1, 0.0));
  EXPECT_EQ(path.size(), 21);
  EXPECT_DOUBLE_EQ(path.progress(), 2.6);
  EXPECT_LT((path.at(2.55) - Eigen::Vector3d(2.5, 0.05, 0.0)).norm(), 1e-12);

  // Steps not a divisor of the spacing (0.02 m steps, 0.05 m spacing along a diagonal): the
  // points lie spacing to spacing + step apart.
  TargetPath diagonal(4096, 0.05, 0.5);
  const Eigen::Vector3d u = Eigen::Vector3d(1.0, -2.0, 2.0) / 3.0;
  diagonal.reset(Eigen::Vector3d(1.0, 2.0, 3.0), u);
  for (int k = 1; k <= 500; ++k) {
    diagonal.record(Eigen::Vector3d(1.0, 2.0, 3.0) + 0.02 * k * u);
  }
  EXPECT_NEAR(diagonal.progress(), 10.0, 1e-9);
  EXPECT_GE(diagonal.size(), 1 + static_cast<int>(10.0 / 0.06));
  EXPECT_LE(diagonal.size(), 1 + static_cast<int>(10.0 / 0.05));
  for (const double sigma : {-3.0, 0.0, 0.3, 4.77, 9.99, 10.0}) {  // virtual road included
    EXPECT_LT((diagonal.at(sigma) - (Eigen::Vector3d(1.0, 2.0, 3.0) + sigma * u)).norm(), 1e-9)
        << sigma;
  }
}

/// On a circle the polyline's arc length falls short of the driven arc by the chord error only:
/// a chord h of a circle of radius R is short of its arc by about h^3 / (24 R^2).
TEST(TargetPath, ProgressOnACircleIsTheArcLengthWithinTheChordError) {
  const double radius = 2.0;
  const double step = 0.01;
  const double spacing = 0.05;
  TargetPath path(4096, spacing, 0.5);
  path.reset(onCircle(radius, 0.0), Eigen::Vector3d::UnitY());
  const int steps = static_cast<int>(3.0 * kPi * radius / step);  // one and a half rounds
  for (int k = 1; k <= steps; ++k) {
    path.record(onCircle(radius, k * step / radius));
    const double driven = k * step;
    const double chord = spacing + step;  // the longest segment
    const double shortfall = driven * chord * chord / (24.0 * radius * radius) + 1e-9;
    ASSERT_LE(path.progress(), driven + 1e-9) << k;
    ASSERT_GE(path.progress(), driven - shortfall) << k;
  }
  // The recorded points are on the circle, the path between them inside it by a sagitta at most;
  // P(sigma) is where the target was at about arc sigma.
  const double sagitta = (spacing + step) * (spacing + step) / (8.0 * radius);
  const double drift =
      steps * step * (spacing + step) * (spacing + step) / (24.0 * radius * radius);
  for (double sigma = 0.0; sigma <= path.progress(); sigma += 0.013) {
    const Eigen::Vector3d p = path.at(sigma);
    EXPECT_LE(p.norm(), radius + 1e-9) << sigma;
    EXPECT_GE(p.norm(), radius - sagitta - 1e-9) << sigma;
    EXPECT_LT((p - onCircle(radius, sigma / radius)).norm(), drift + sagitta + step) << sigma;
  }
  expectArcLengthParametrised(path, -1.0, path.progress() + 1.0);
}

TEST(TargetPath, AtIsContinuousAndExactOnRecordedPoints) {
  TargetPath path(256, kSpacing, 0.5);
  path.reset(Eigen::Vector3d(1.0, 1.0, 0.0), Eigen::Vector3d::UnitX());
  driveTo(&path, Eigen::Vector3d(1.0, 1.0, 0.0), Eigen::Vector3d(3.0, 1.0, 0.0), kStep);
  driveTo(&path, Eigen::Vector3d(3.0, 1.0, 0.0), Eigen::Vector3d(3.0, 3.0, 1.0), 0.03);
  driveTo(&path, Eigen::Vector3d(3.0, 3.0, 1.0), Eigen::Vector3d(0.5, 3.3, 1.0), 0.07);
  // Exact at the corner (2 m of exact steps) and on the points before it.
  for (int j = 0; j <= 16; ++j) {
    EXPECT_EQ(path.at(j * kSpacing), Eigen::Vector3d(1.0 + j * kSpacing, 1.0, 0.0)) << j;
  }
  // On the later legs the path passes through the corners (up to a recorded point's rounding).
  EXPECT_LT((path.at(2.0 + std::sqrt(5.0)) - Eigen::Vector3d(3.0, 3.0, 1.0)).norm(), 0.2);
  EXPECT_LT((path.at(path.progress()) - Eigen::Vector3d(0.5, 3.3, 1.0)).norm(), 1e-9);
  expectArcLengthParametrised(path, -2.0, path.progress() + 2.0);
  // Beyond the target the path goes on straight.
  // (Here the target sits on its latest recorded point, so "along the latest leg" is the reset
  // direction: only the unit speed is checked.)
  const Eigen::Vector3d beyond = path.at(path.progress() + 1.0) - path.at(path.progress());
  EXPECT_NEAR(beyond.norm(), 1.0, 1e-9);
}

TEST(TargetPath, VirtualRoadRunsBackAlongTheResetDirectionWhileTheStartIsKept) {
  const Eigen::Vector3d start(1.0, 2.0, -1.0);
  TargetPath path(64, kSpacing, 0.5);
  path.reset(start, Eigen::Vector3d(0.0, 2.0, 0.0));  // not unit: normalised
  for (const double tau : {0.0, 0.5, 3.0, 100.0}) {
    EXPECT_LT((path.at(-tau) - (start - tau * Eigen::Vector3d::UnitY())).norm(), 1e-12) << tau;
  }
  // A zero or non-finite direction: along x.
  path.reset(start, Eigen::Vector3d::Zero());
  EXPECT_LT((path.at(-2.0) - (start - 2.0 * Eigen::Vector3d::UnitX())).norm(), 1e-12);
  path.reset(start, Eigen::Vector3d(std::nan(""), 1.0, 0.0));
  EXPECT_LT((path.at(-2.0) - (start - 2.0 * Eigen::Vector3d::UnitX())).norm(), 1e-12);

  // The target drives off at right angles to the reset direction: the road stays the one the
  // convoy came on, along the reset direction, as long as the start is the oldest point.
  path.reset(start, Eigen::Vector3d::UnitY());
  const Eigen::Vector3d e = Eigen::Vector3d(3.0, 0.0, 4.0) / 5.0;  // the first leg
  driveTo(&path, start, start + 2.0 * e, 0.01);
  driveTo(&path, start + 2.0 * e, start + 2.0 * e + Eigen::Vector3d(0.0, 1.0, 0.0), 0.01);
  ASSERT_GE(path.size(), 2);
  EXPECT_EQ(path.oldestArc(), 0.0);
  for (const double tau : {0.1, 1.0, 7.5}) {
    EXPECT_LT((path.at(-tau) - (start - tau * Eigen::Vector3d::UnitY())).norm(), 1e-12) << tau;
  }
}

/// The ring keeps the latest capacity points: the oldest go, at() on the recent arcs stays on the
/// driven path and before the oldest kept point the virtual road runs along the oldest kept
/// segment.
TEST(TargetPath, RingDropsTheOldestPointsAtCapacity) {
  TargetPath path(16, kSpacing, 0.5);
  path.reset(Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitX());
  driveTo(&path, Eigen::Vector3d::Zero(), Eigen::Vector3d(10.0, 0.0, 0.0), kStep);
  EXPECT_EQ(path.size(), 16);
  EXPECT_EQ(path.oldestArc(), 10.0 - 15 * kSpacing);
  driveTo(&path, Eigen::Vector3d(10.0, 0.0, 0.0), Eigen::Vector3d(10.0, 10.0, 0.0), kStep);
  EXPECT_EQ(path.size(), 16);
  EXPECT_EQ(path.progress(), 20.0);
  EXPECT_EQ(path.oldestArc(), 20.0 - 15 * kSpacing);
  for (int k = 0; k <= 15; ++k) {
    EXPECT_EQ(path.at(20.0 - k * kSpacing), Eigen::Vector3d(10.0, 10.0 - k * kSpacing, 0.0)) << k;
  }
  // Before the oldest kept point: straight back along y, not the x leg driven 12 m back.
  EXPECT_EQ(path.at(8.0), Eigen::Vector3d(10.0, -2.0, 0.0));

  // On a circle, many times round a small ring: the kept arcs stay on the circle.
  const double radius = 1.0;
  TargetPath ring(64, 0.05, 0.5);
  ring.reset(onCircle(radius, 0.0), Eigen::Vector3d::UnitY());
  for (int k = 1; k <= 5000; ++k) {  // 0.01 m steps: 50 m, eight rounds
    ring.record(onCircle(radius, 0.01 * k));
  }
  EXPECT_EQ(ring.size(), 64);
  EXPECT_NEAR(ring.progress(), 50.0, 50.0 * 0.06 * 0.06 / 24.0 + 1e-9);
  EXPECT_GT(ring.oldestArc(), ring.progress() - 63 * 0.06 - 0.05);
  EXPECT_LT(ring.oldestArc(), ring.progress() - 63 * 0.05 + 1e-9);
  const double sagitta = 0.06 * 0.06 / 8.0;
  for (double sigma = ring.oldestArc(); sigma <= ring.progress(); sigma += 0.01) {
    EXPECT_NEAR(ring.at(sigma).norm(), radius - 0.5 * sagitta, 0.5 * sagitta + 1e-9) << sigma;
    // Back along the circle from the target by the arc (the chord error is tiny over 3 m).
    const double back = ring.progress() - sigma;
    EXPECT_LT((ring.at(sigma) - onCircle(radius, 50.0 - back)).norm(), 2e-3) << sigma;
  }
  expectArcLengthParametrised(ring, ring.oldestArc() - 1.0, ring.progress() + 1.0);
}

TEST(TargetPath, RetracingLowersTheProgress) {
  // Straight back over the recorded points: s is the position along the line, exactly.
  TargetPath path(256, kSpacing, 0.5);
  path.reset(Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitX());
  driveTo(&path, Eigen::Vector3d::Zero(), Eigen::Vector3d(5.0, 0.0, 0.0), kStep);
  for (int k = 1; k <= 32; ++k) {
    path.record(Eigen::Vector3d(5.0 - k * kStep, 0.0, 0.0));
    EXPECT_EQ(path.progress(), 5.0 - k * kStep) << k;
  }
  EXPECT_EQ(path.size(), 25);
  driveTo(&path, Eigen::Vector3d(3.0, 0.0, 0.0), Eigen::Vector3d(3.0, 0.0, 1.0), kStep);
  EXPECT_EQ(path.progress(), 4.0);  // and forward again: s grows
  EXPECT_EQ(path.at(3.5), Eigen::Vector3d(3.0, 0.0, 0.5));

  // A step back 0.3 m beside the line (within retrace_width) takes the latest point off; 0.7 m
  // beside it (outside) keeps it: a new way, along which s grows by the distance driven.
  for (const double width : {0.3, 0.7}) {
    TargetPath beside(256, kSpacing, 0.5);
    beside.reset(Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitX());
    driveTo(&beside, Eigen::Vector3d::Zero(), Eigen::Vector3d(5.0, 0.0, 0.0), kStep);
    beside.record(Eigen::Vector3d(5.0 - kStep, width, 0.0));
    const double kept = width < 0.5 ? 5.0 - kSpacing : 5.0;  // the latest point kept
    EXPECT_DOUBLE_EQ(beside.progress(), kept + std::hypot(5.0 - kStep - kept, width)) << width;
    if (width > 0.5) {
      double previous = beside.progress();
      for (int k = 2; k <= 32; ++k) {
        beside.record(Eigen::Vector3d(5.0 - k * kStep, width, 0.0));
        EXPECT_GE(beside.progress(), previous + kStep - 1e-12) << k;
        previous = beside.progress();
      }
    }
  }

  // Behind the only point, on the virtual road: the point slides back and s goes negative.
  TargetPath start(16, kSpacing, 0.5);
  start.reset(Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitX());
  for (int k = 1; k <= 16; ++k) {
    start.record(Eigen::Vector3d(-k * kStep, 0.0, 0.0));
    EXPECT_EQ(start.progress(), -k * kStep) << k;
    EXPECT_EQ(start.size(), 1);
  }
  EXPECT_EQ(start.at(-1.5), Eigen::Vector3d(-1.5, 0.0, 0.0));
  start.record(Eigen::Vector3d::Zero());  // and forward again
  EXPECT_EQ(start.progress(), 0.0);
  EXPECT_EQ(start.size(), 2);
}

/// A target that reverses over its path drifting sideways, gradually, to @p width (default spacing
/// 0.05 m and retrace_width 0.5 m, 1 m/s at 100 Hz): (C1) says it takes the points it drove back
/// over off again, so s goes down while it reverses; s stays within the drift of the position
/// along the line.
/// A point beside the path is not recorded while the target retraces, so the latest segment
/// stays on the path and the target stays "behind" it.
TEST(TargetPath, ReversingWithASidewaysDriftWithinRetraceWidthLowersTheProgress) {
  for (const double width : {0.03, 0.1, 0.3}) {
    TargetPath path(4096, 0.05, 0.5);
    path.reset(Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitX());
    driveTo(&path, Eigen::Vector3d::Zero(), Eigen::Vector3d(5.0, 0.0, 0.0), 0.01);
    double worst = 0.0;  // the largest excess of s over x + drift + spacing
    for (int k = 1; k <= 200; ++k) {
      const double x = 5.0 - 0.01 * k;
      const double y = width * k / 200.0;
      path.record(Eigen::Vector3d(x, y, 0.0));
      EXPECT_GE(path.progress(), x - 1e-9) << width << " " << k;
      worst = std::max(worst, path.progress() - (x + y + 0.05));
    }
    EXPECT_LE(worst, 0.0) << "drift " << width << ": s exceeds x + drift + spacing by " << worst
                          << " m (final s " << path.progress() << ", x 3)";
  }
}

TEST(TargetPath, NonFinitePositionsAreIgnored) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  TargetPath clean(128, 0.05, 0.5);
  TargetPath noisy(128, 0.05, 0.5);
  clean.reset(Eigen::Vector3d(0.0, 0.0, 1.0), Eigen::Vector3d::UnitX());
  noisy.reset(Eigen::Vector3d(0.0, 0.0, 1.0), Eigen::Vector3d::UnitX());
  for (int k = 1; k <= 400; ++k) {
    const Eigen::Vector3d p(0.02 * k, std::sin(0.01 * k), 1.0);
    clean.record(p);
    noisy.record(p);
    if (k % 7 == 0) {
      noisy.record(Eigen::Vector3d(nan, 0.0, 1.0));
      noisy.record(Eigen::Vector3d(0.0, inf, 1.0));
      noisy.record(Eigen::Vector3d(0.0, 0.0, -inf));
      ASSERT_EQ(noisy.progress(), clean.progress()) << k;
    }
  }
  EXPECT_EQ(noisy.size(), clean.size());
  for (double sigma = -1.0; sigma <= clean.progress() + 1.0; sigma += 0.01) {
    EXPECT_EQ(noisy.at(sigma), clean.at(sigma)) << sigma;
  }
  noisy.reset(Eigen::Vector3d(nan, 0.0, 0.0), Eigen::Vector3d::UnitY());  // a non-finite start
  EXPECT_TRUE(noisy.at(-1.0).allFinite());
}

}  // namespace
}  // namespace projection_collision_avoidance
