/// Each law of PaperLaws.hpp on its own, against values worked out by hand from its equation
/// (doc/math.md): a double integrator on one axis, small matrices.

#include <cmath>
#include <limits>

#include <gtest/gtest.h>

#include "projection_collision_avoidance/core/PaperLaws.hpp"

namespace projection_collision_avoidance {
namespace {

using Dims = DoubleIntegrator1D;  // x = [p; v], u = a, y = x
using Input = Dims::InputVector;
using Output = Dims::OutputVector;
using State = Dims::StateVector;

TEST(PaperLaws, BaselineIsGainTimesOutput) {  // (2)
  Dims::FeedbackGainMatrix g;
  g << 2.0, 3.0;
  EXPECT_DOUBLE_EQ(baselineCommand<Dims>(g, Output(1.5, -0.5))(0), 2.0 * 1.5 - 3.0 * 0.5);
}

TEST(PaperLaws, TrackerActsOnOutputErrorAndEstimate) {  // (19)
  Dims::FeedbackGainMatrix ge;
  ge << 1.0, 4.0;
  Dims::FeedbackGainMatrix s21;
  s21 << -2.0, 0.5;
  const Output y(3.0, 1.0);
  const Output y_hat(1.0, 2.0);
  // G_e (y - y_hat) + S_21 y_hat = [1 4] [2; -1] + [-2 0.5] [1; 2] = -2 + -1 = -3
  EXPECT_DOUBLE_EQ((trackerCommand<Dims>(ge, s21, y, y_hat))(0), -3.0);
}

TEST(PaperLaws, AugmentedCommandSumsThenSaturates) {  // (10)
  Input command;
  const Input baseline(1.0);
  const Input tracker(2.0);
  const Input feedforward(0.5);
  const Input headway(-0.25);
  EXPECT_FALSE(augmentedCommand<Dims>(baseline, tracker, feedforward, nullptr, 10.0, &command));
  EXPECT_DOUBLE_EQ(command(0), 3.5);
  EXPECT_FALSE(augmentedCommand<Dims>(baseline, tracker, feedforward, &headway, 10.0, &command));
  EXPECT_DOUBLE_EQ(command(0), 3.25);
  EXPECT_TRUE(augmentedCommand<Dims>(baseline, tracker, feedforward, &headway, 2.0, &command));
  EXPECT_DOUBLE_EQ(command(0), 2.0);  // sat() keeps the direction, length 2
  const double inf = std::numeric_limits<double>::infinity();
  EXPECT_FALSE(augmentedCommand<Dims>(baseline, tracker, feedforward, nullptr, inf, &command));
  EXPECT_DOUBLE_EQ(command(0), 3.5);
}

TEST(PaperLaws, SaturationScalesOntoTheBallInTheSameDirection) {  // sat() of (10)
  Eigen::Vector2d command(3.0, 4.0);
  EXPECT_TRUE(saturateCommand(&command, 1.0));
  EXPECT_NEAR(command(0), 0.6, 1e-15);
  EXPECT_NEAR(command(1), 0.8, 1e-15);
  EXPECT_FALSE(saturateCommand(&command, 1.0));  // on the boundary: unchanged
  Eigen::Vector2d nan(std::nan(""), 0.0);
  saturateCommand(&nan, 1.0);
  EXPECT_FALSE(nan.allFinite());  // a non-finite command stays so
}

TEST(PaperLaws, ActingAugmentationIsWhatSaturationLeft) {  // (10) -> (11)
  // u_2 = 2 after sat(), G y = 1, u_ff = 0.5: what acts of u_a is 0.5.
  EXPECT_DOUBLE_EQ(actingAugmentation(Input(2.0), Input(1.0), Input(0.5))(0), 0.5);
}

TEST(PaperLaws, LeaderInputDriftIsTheUnsharedPartOfTheAcceleration) {  // w of (11)
  Dims::InputMatrix b(0.0, 1.0);
  const State w = leaderInputDrift<Dims>(b, Input(3.0), Input(1.0));
  EXPECT_DOUBLE_EQ(w(0), 0.0);
  EXPECT_DOUBLE_EQ(w(1), 2.0);
}

TEST(PaperLaws, EstimatorHeldInputAndDrift) {  // (11)
  Dims::InputMatrix b(0.0, 1.0);
  Dims::ObserverGainMatrix l;
  l << 2.0, 0.0, 0.0, 3.0;
  const Output y(1.0, -1.0);
  const State w(0.5, 0.25);
  // c = w - B u_a - L y = [0.5; 0.25] - [0; 2] - [2; -3] = [-1.5; 1.25]
  const State c = estimatorHeldInput<Dims>(b, l, y, Input(2.0), w);
  EXPECT_DOUBLE_EQ(c(0), -1.5);
  EXPECT_DOUBLE_EQ(c(1), 1.25);
  Dims::StateMatrix f;
  f << 0.0, 1.0, -2.0, -3.0;
  // h = F xi_hat + c = [[0 1] [-2 -3]] [1; 2] + c = [2; -8] + c = [0.5; -6.75]
  const State h = estimatorDrift<Dims>(f, State(1.0, 2.0), c);
  EXPECT_DOUBLE_EQ(h(0), 0.5);
  EXPECT_DOUBLE_EQ(h(1), -6.75);
}

TEST(PaperLaws, LeaderAccelerationAddsTheDisturbancesAccelerationPart) {
  Eigen::Matrix<double, 1, 2> pinv_b(0.0, 1.0);
  const Input a = leaderAcceleration(Input(1.0), pinv_b, State(5.0, -0.25));
  EXPECT_DOUBLE_EQ(a(0), 0.75);  // the position-rate part of u_d does not count
}

}  // namespace
}  // namespace projection_collision_avoidance
