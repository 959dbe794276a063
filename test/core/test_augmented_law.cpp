/// AugmentedLaw, the one composition of (2), (19), (S1) and (10), on the math note's 1-D
/// controller (G = [1, 1.4], G_e = [10, 5], S_21 = 0): each term worked out by hand.

#include <limits>

#include <gtest/gtest.h>

#include "projection_collision_avoidance/core/AugmentedLaw.hpp"
#include "projection_collision_avoidance/core/ControllerDesign.hpp"

#include "TestScenarios.hpp"

namespace projection_collision_avoidance {
namespace {

using Dims = DoubleIntegrator1D;
using Input = Dims::InputVector;
using Output = Dims::OutputVector;
using State = Dims::StateVector;

const Output kY(1.0, 0.5);      // y = xi
const Output kYHat(0.5, 0.25);  // C xi_hat
// G y = 1 + 0.7 = 1.7;  u_a = G_e (y - y_hat) = 10 * 0.5 + 5 * 0.25 = 6.25

TEST(AugmentedLaw, SumsBaselineTrackerAndFeedforward) {
  const AugmentedLaw<Dims> law(ControllerDesign::create(testing::paperParameters()));
  AugmentedTerms<Dims> terms;
  law.compose(kY, kYHat, Input(0.5), nullptr, &terms);
  EXPECT_DOUBLE_EQ(terms.baseline(0), 1.7);
  EXPECT_DOUBLE_EQ(terms.tracker(0), 6.25);
  EXPECT_DOUBLE_EQ(terms.command(0), 8.45);
  EXPECT_FALSE(terms.saturated);
  EXPECT_FALSE(terms.headway_acting);
  // Neither limit acted: what acts is u_a itself.
  EXPECT_DOUBLE_EQ(law.acting(terms, terms.command, Input(0.5), false)(0), 6.25);
  // A rate limit cut the command to 2: what acts is u_2 - G y - u_ff = -0.2.
  EXPECT_DOUBLE_EQ(law.acting(terms, Input(2.0), Input(0.5), true)(0), 2.0 - 1.7 - 0.5);
}

TEST(AugmentedLaw, SaturatesTheSumAndCountsWhatActs) {
  ControllerParameters p = testing::paperParameters();
  p.acceleration_limit = 3.0;
  const AugmentedLaw<Dims> law(ControllerDesign::create(p));
  AugmentedTerms<Dims> terms;
  law.compose(kY, kYHat, Input(0.0), nullptr, &terms);
  EXPECT_TRUE(terms.saturated);
  EXPECT_DOUBLE_EQ(terms.command(0), 3.0);
  EXPECT_DOUBLE_EQ(law.acting(terms, terms.command, Input(0.0), false)(0), 3.0 - 1.7);
}

TEST(AugmentedLaw, HeadwayActsOnlyWithAFiniteOwnState) {
  ControllerParameters p = testing::paperParameters();
  p.time_headway = 0.5;
  const ControllerDesign design = ControllerDesign::create(p);
  const AugmentedLaw<Dims> law(design);
  AugmentedTerms<Dims> terms;
  const State own(0.0, 2.0);  // moving at 2 m/s
  law.compose(kY, kYHat, Input(0.0), &own, &terms);
  ASSERT_TRUE(terms.headway_acting);
  const double headway = (design.headway_gain * Eigen::Vector2d(0.0, 2.0))(0);
  EXPECT_NE(headway, 0.0);
  EXPECT_DOUBLE_EQ(terms.headway(0), headway);
  EXPECT_DOUBLE_EQ(terms.command(0), 1.7 + 6.25 + headway);
  EXPECT_DOUBLE_EQ(law.acting(terms, terms.command, Input(0.0), false)(0), 6.25 + headway);
  const State nan(std::numeric_limits<double>::quiet_NaN(), 0.0);
  law.compose(kY, kYHat, Input(0.0), &nan, &terms);
  EXPECT_FALSE(terms.headway_acting);
  EXPECT_DOUBLE_EQ(terms.command(0), 7.95);
}

TEST(AugmentedLaw, KnownDriftOnlyWhenSharedIntoTheEstimator) {
  ControllerParameters p = testing::paperParameters();
  const Input a1(3.0);
  EXPECT_TRUE(AugmentedLaw<Dims>(ControllerDesign::create(p)).knownDrift(&a1, Input(1.0)).isZero());
  p.leader_input_in_estimator = true;
  const AugmentedLaw<Dims> law(ControllerDesign::create(p));
  const State w = law.knownDrift(&a1, Input(1.0));  // B (a_1 - u_ff) = [0; 2]
  EXPECT_DOUBLE_EQ(w(0), 0.0);
  EXPECT_DOUBLE_EQ(w(1), 2.0);
  EXPECT_TRUE(law.knownDrift(nullptr, Input(1.0)).isZero());  // a_1 unknown
}

}  // namespace
}  // namespace projection_collision_avoidance
