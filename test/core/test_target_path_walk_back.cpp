/// walkBack() of the convoy's path (doc/math.md, "Convoys on the target's path", (C2)): the
/// largest arc at or below sigma at least a chord from the target, against a brute-force search.

#include <cmath>
#include <limits>
#include <random>

#include <Eigen/Core>
#include <gtest/gtest.h>

#include "projection_collision_avoidance/core/TargetPath.hpp"

#include "TargetPathDrives.hpp"

namespace projection_collision_avoidance {
namespace {

constexpr double kPi = 3.141592653589793;

/// walkBack(sigma, target, chord) against a brute-force search of P on a grid of @p h: the result
/// is <= sigma, at least chord from the target, and within h of the largest far grid point.
void expectWalkBackMatchesBruteForce(const TargetPath& path, double sigma,
                                     const Eigen::Vector3d& target, double chord) {
  const double walked = path.walkBack(sigma, target, chord);
  EXPECT_LE(walked, sigma);
  EXPECT_GE((target - path.at(walked)).norm(), chord * (1.0 - 1e-12)) << sigma << " " << chord;
  const double h = 1e-4;
  double brute = std::numeric_limits<double>::quiet_NaN();
  for (double candidate = sigma; candidate > path.oldestArc() - 100.0; candidate -= h) {
    if ((target - path.at(candidate)).norm() >= chord) {
      brute = candidate;
      break;
    }
  }
  ASSERT_TRUE(std::isfinite(brute)) << "no far point found by brute force";
  if (brute == sigma) {
    EXPECT_EQ(walked, sigma);
  }
  // The true answer lies in [brute, brute + h): the grid point above brute is closer than chord.
  EXPECT_GE(walked, brute - 1e-9) << "walkBack missed a far point: sigma " << sigma << " chord "
                                  << chord << " target " << target.transpose();
  EXPECT_LT(walked, brute + h + 1e-9) << "sigma " << sigma << " chord " << chord;
}
/// walkBack on a U-turn: straight 4 m, half a circle of radius 1, 2 m back beside the first leg.
TEST(TargetPath, WalkBackOnAUTurnMatchesBruteForce) {
  TargetPath path(4096, 0.05, 0.5);
  path.reset(Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitX());
  driveTo(&path, Eigen::Vector3d::Zero(), Eigen::Vector3d(4.0, 0.0, 0.0), 0.01);
  for (int k = 1; k <= 314; ++k) {
    path.record(Eigen::Vector3d(4.0, 1.0, 0.0) + onCircle(1.0, -0.5 * kPi + 0.01 * k));
  }
  const Eigen::Vector3d end(4.0, 2.0, 0.0);
  driveTo(&path, path.at(path.progress()), end, 0.01);
  driveTo(&path, end, Eigen::Vector3d(2.0, 2.0, 0.0), 0.01);
  const Eigen::Vector3d target(2.0, 2.0, 0.0);
  const double s = path.progress();
  for (const double chord : {0.3, 1.0, 1.4, 2.1, 2.5, 3.0, 6.0}) {
    for (const double gap : {0.0, 0.5, 1.5, 3.0, 5.0, 9.0, 20.0}) {
      expectWalkBackMatchesBruteForce(path, s - gap, target, chord);
    }
  }
  // Other targets (the function's contract holds for any point), a few from each side.
  std::mt19937 random(3);
  std::uniform_real_distribution<double> x(-2.0, 7.0);
  std::uniform_real_distribution<double> y(-2.0, 4.0);
  std::uniform_real_distribution<double> sigma(-3.0, s + 1.0);
  std::uniform_real_distribution<double> chord(0.1, 4.0);
  for (int trial = 0; trial < 60; ++trial) {
    expectWalkBackMatchesBruteForce(path, sigma(random), Eigen::Vector3d(x(random), y(random), 0.0),
                                    chord(random));
  }
}

TEST(TargetPath, WalkBackOnACircleAndOnTheVirtualRoadMatchesBruteForce) {
  const double radius = 1.0;
  TargetPath path(4096, 0.05, 0.5);
  path.reset(onCircle(radius, 0.0), Eigen::Vector3d::UnitY());
  const int steps = 1100;  // 0.01 rad steps, most of two rounds
  for (int k = 1; k <= steps; ++k) {
    path.record(onCircle(radius, 0.01 * k));
  }
  const Eigen::Vector3d target = onCircle(radius, 0.01 * steps);
  const double s = path.progress();
  for (const double chord : {0.2, 0.9, 1.4, 1.9, 1.99}) {
    for (const double gap : {0.0, 0.3, 1.0, 2.5, 4.0, 6.5}) {
      expectWalkBackMatchesBruteForce(path, s - gap, target, chord);
    }
  }
  // A chord wider than the circle: back onto the virtual road before the start.
  const double walked = path.walkBack(s - 1.0, target, 2.5);
  EXPECT_LT(walked, path.oldestArc());
  expectWalkBackMatchesBruteForce(path, s - 1.0, target, 2.5);

  // One point only: the whole path is the virtual road and the line to the target.
  TargetPath road(16, 0.05, 0.5);
  road.reset(Eigen::Vector3d(1.0, 0.0, 0.0), Eigen::Vector3d(1.0, 1.0, 0.0));
  for (const Eigen::Vector3d& point :
       {Eigen::Vector3d(1.0, 0.0, 0.0), Eigen::Vector3d(0.0, 0.0, 0.0),
        Eigen::Vector3d(-2.0, -1.0, 0.5), Eigen::Vector3d(1.0, 3.0, 0.0)}) {
    for (const double chord : {0.5, 1.4, 3.0}) {
      for (const double sigma : {0.0, -0.5, -2.0, 1.0}) {
        expectWalkBackMatchesBruteForce(road, sigma, point, chord);
      }
    }
  }
  // From the target's own position at the start: the goal is exactly chord back along the road.
  EXPECT_NEAR(road.walkBack(0.0, Eigen::Vector3d(1.0, 0.0, 0.0), 1.4), -1.4, 1e-12);
}

}  // namespace
}  // namespace projection_collision_avoidance
