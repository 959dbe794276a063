// The α-β filter that reconstructs the relative velocity from relative positions
// (RelativeVelocityFilter): its start, its convergence rate, its lag under acceleration and its
// refusals.
#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include <gtest/gtest.h>

#include "projection_collision_avoidance/vehicle/RelativeVelocityFilter.hpp"

namespace projection_collision_avoidance {
namespace {

VelocityFilterOptions optionsOf(int axes, double bandwidth) {
  VelocityFilterOptions o;
  o.axes = axes;
  o.bandwidth = bandwidth;
  o.max_gap = 0.5;
  return o;
}

TEST(RelativeVelocityFilter, ConstantVelocityIsExactFromTheSecondPosition) {
  RelativeVelocityFilter filter(optionsOf(2, 20.0));
  const Eigen::Vector3d v(1.5, -0.25, 7.0);  // the third axis is ignored
  Eigen::VectorXd state;
  EXPECT_EQ(filter.update(0.0, Eigen::Vector3d(1, 2, 3), &state), VelocityFilterVerdict::kStarted);
  for (int k = 1; k <= 50; ++k) {
    const double t = 0.01 * k;
    const Eigen::Vector3d p = Eigen::Vector3d(1, 2, 3) + v * t;
    ASSERT_EQ(filter.update(t, p, &state), VelocityFilterVerdict::kEstimated);
    ASSERT_EQ(state.size(), 4);
    EXPECT_EQ(state(0), p(0));  // the position as measured
    EXPECT_EQ(state(1), p(1));
    EXPECT_NEAR(state(2), v(0), 1e-9);
    EXPECT_NEAR(state(3), v(1), 1e-9);
  }
}

TEST(RelativeVelocityFilter, AVelocityErrorDecaysWithTheDoublePoleAtExpMinusOmegaDt) {
  // A step of the true velocity at t = 0.1 s: the error of v̂ then obeys the second-order
  // recursion with the double root θ = e^(−ω Δt), e_k = (c0 + c1 k) θ^k, so after n steps it is
  // below (1 + n) θ^n times a constant: check the ratio of the errors 40 and 80 steps later.
  const double omega = 10.0;
  const double dt = 0.01;
  RelativeVelocityFilter filter(optionsOf(1, omega));
  Eigen::VectorXd state;
  double p = 0.0;
  filter.update(0.0, Eigen::Vector3d(p, 0, 0), &state);
  double error_40 = 0.0;
  double error_80 = 0.0;
  for (int k = 1; k <= 100; ++k) {
    const double v = k > 10 ? 1.0 : 0.0;
    p += v * dt;
    filter.update(k * dt, Eigen::Vector3d(p, 0, 0), &state);
    if (k == 50) {
      error_40 = std::abs(state(1) - v);
    }
    if (k == 90) {
      error_80 = std::abs(state(1) - v);
    }
  }
  const double theta = std::exp(-omega * dt);
  ASSERT_GT(error_40, 1e-6);
  // Each step multiplies by θ and the polynomial factor (c0 + c1 k): for 40 more steps the
  // ratio is θ^40 (c0 + c1 (k+40)) / (c0 + c1 k), between θ^40 and 3 θ^40 here.
  EXPECT_LT(error_80 / error_40, 3.0 * std::pow(theta, 40));
  EXPECT_GT(error_80 / error_40, std::pow(theta, 40));
}

TEST(RelativeVelocityFilter, UnderConstantAccelerationTheVelocityLagsByTheStatedAmount) {
  for (const double omega : {5.0, 20.0, 50.0}) {
    const double dt = 0.01;
    const double a = -2.0;
    VelocityFilterOptions o = optionsOf(3, omega);
    o.max_speed = 100.0;  // 40 √2 m/s after 20 s
    RelativeVelocityFilter filter(o);
    Eigen::VectorXd state;
    for (int k = 0; k <= 2000; ++k) {
      const double t = k * dt;
      filter.update(t, Eigen::Vector3d(0.5 * a * t * t, 0, -0.5 * a * t * t), &state);
    }
    const double theta = std::exp(-omega * dt);
    const double lag = a * dt * ((1 + theta) / (1 - theta) - 0.5);
    const double v = a * 2000 * dt;
    EXPECT_NEAR(state(3), v - lag, 1e-6 * std::abs(v)) << "omega " << omega;
    EXPECT_NEAR(state(5), -(v - lag), 1e-6 * std::abs(v)) << "omega " << omega;
    EXPECT_NEAR(lag, 2 * a / omega, 0.02 * std::abs(2 * a / omega) + 1.5 * std::abs(a) * dt);
  }
}

TEST(RelativeVelocityFilter, IrregularStampsStillConverge) {
  RelativeVelocityFilter filter(optionsOf(2, 20.0));
  Eigen::VectorXd state;
  const Eigen::Vector3d v(-3.0, 2.0, 0.0);
  double t = 0.0;
  for (int k = 0; k < 400; ++k) {
    t += 0.004 + 0.012 * ((k * 7919) % 13) / 13.0;  // 4 to 16 ms
    filter.update(t, Eigen::Vector3d(0.3, -1.0, 0.0) + v * t, &state);
  }
  EXPECT_NEAR(state(2), v(0), 1e-9);
  EXPECT_NEAR(state(3), v(1), 1e-9);
}

TEST(RelativeVelocityFilter, AGapStartsAgainAndOldOrRepeatedStampsAreIgnored) {
  RelativeVelocityFilter filter(optionsOf(1, 20.0));
  Eigen::VectorXd state;
  EXPECT_EQ(filter.update(1.0, Eigen::Vector3d(0, 0, 0), &state), VelocityFilterVerdict::kStarted);
  EXPECT_EQ(filter.update(1.0, Eigen::Vector3d(5, 0, 0), &state),
            VelocityFilterVerdict::kNotIncreasing);
  EXPECT_EQ(filter.update(0.5, Eigen::Vector3d(5, 0, 0), &state),
            VelocityFilterVerdict::kNotIncreasing);
  EXPECT_EQ(filter.update(1.1, Eigen::Vector3d(1, 0, 0), &state),
            VelocityFilterVerdict::kEstimated);
  EXPECT_NEAR(state(1), 10.0, 1e-12);
  // 0.6 s later than the last: beyond max_gap, so no velocity from across the gap.
  EXPECT_EQ(filter.update(1.7, Eigen::Vector3d(100, 0, 0), &state),
            VelocityFilterVerdict::kStarted);
  EXPECT_EQ(filter.update(1.8, Eigen::Vector3d(100.2, 0, 0), &state),
            VelocityFilterVerdict::kEstimated);
  EXPECT_NEAR(state(1), 2.0, 1e-9);
  filter.reset();
  EXPECT_EQ(filter.update(1.9, Eigen::Vector3d(0, 0, 0), &state), VelocityFilterVerdict::kStarted);
}

TEST(RelativeVelocityFilter, NonFiniteInputsAreRefusedAndLeaveTheEstimateAlone) {
  RelativeVelocityFilter filter(optionsOf(2, 20.0));
  Eigen::VectorXd state;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  filter.update(0.0, Eigen::Vector3d(0, 0, 0), &state);
  filter.update(0.01, Eigen::Vector3d(0.01, 0, 0), &state);
  EXPECT_EQ(filter.update(0.02, Eigen::Vector3d(nan, 0, 0), &state),
            VelocityFilterVerdict::kRefused);
  EXPECT_EQ(filter.update(0.02, Eigen::Vector3d(0, inf, 0), &state),
            VelocityFilterVerdict::kRefused);
  EXPECT_EQ(filter.update(nan, Eigen::Vector3d(0, 0, 0), &state), VelocityFilterVerdict::kRefused);
  // A NaN on an axis beyond the model's is not read.
  EXPECT_EQ(filter.update(0.02, Eigen::Vector3d(0.02, 0, nan), &state),
            VelocityFilterVerdict::kEstimated);
  EXPECT_NEAR(state(2), 1.0, 1e-12);
  // A jump to ±1e308 overflows the estimate: refused, and the filter starts again.
  EXPECT_EQ(filter.update(0.03, Eigen::Vector3d(1e308, 0, 0), &state),
            VelocityFilterVerdict::kRefused);
  EXPECT_EQ(filter.update(0.04, Eigen::Vector3d(-1e308, 0, 0), &state),
            VelocityFilterVerdict::kStarted);
}

TEST(RelativeVelocityFilter, OptionsOutOfRangeAreRefusedByName) {
  const auto refused = [](VelocityFilterOptions o, const char* key) {
    try {
      RelativeVelocityFilter filter(o);
      ADD_FAILURE() << key << " accepted";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(key), std::string::npos) << e.what();
    }
  };
  VelocityFilterOptions o = optionsOf(2, 20.0);
  o.axes = 4;
  refused(o, "axes");
  o = optionsOf(2, 0.0);
  refused(o, "bandwidth");
  o = optionsOf(2, std::numeric_limits<double>::infinity());
  refused(o, "bandwidth");
  o = optionsOf(2, 20.0);
  o.max_gap = -1.0;
  refused(o, "max_gap");
  o = optionsOf(2, 20.0);
  o.min_interval = 0.0;
  refused(o, "min_interval");
  o.min_interval = o.max_gap;  // no position could ever be used
  refused(o, "min_interval");
  o = optionsOf(2, 20.0);
  o.max_speed = 0.0;
  refused(o, "max_speed");
  o.max_speed = std::numeric_limits<double>::infinity();
  refused(o, "max_speed");
}

TEST(RelativeVelocityFilter, APositionTooSoonAfterTheLastUsedIsIgnored) {
  RelativeVelocityFilter filter(optionsOf(1, 20.0));  // min_interval 0.005 s
  Eigen::VectorXd state;
  ASSERT_EQ(filter.update(0.0, Eigen::Vector3d(0, 0, 0), &state), VelocityFilterVerdict::kStarted);
  EXPECT_EQ(filter.update(0.004, Eigen::Vector3d(0.5, 0, 0), &state),
            VelocityFilterVerdict::kTooSoon);
  // Measured from the last position used (t = 0), not from the ignored one.
  ASSERT_EQ(filter.update(0.006, Eigen::Vector3d(0.006, 0, 0), &state),
            VelocityFilterVerdict::kEstimated);
  EXPECT_NEAR(state(1), 1.0, 1e-9);
  // While estimating too.
  EXPECT_EQ(filter.update(0.0069, Eigen::Vector3d(3.0, 0, 0), &state),
            VelocityFilterVerdict::kTooSoon);
  ASSERT_EQ(filter.update(0.016, Eigen::Vector3d(0.016, 0, 0), &state),
            VelocityFilterVerdict::kEstimated);
  EXPECT_NEAR(state(1), 1.0, 1e-9);
}

TEST(RelativeVelocityFilter, TwoPositionsAMicrosecondApartAfterAGapGiveNoPhantomVelocity) {
  // After a gap beyond max_gap, two positions 1 µs and 1 cm apart: their difference quotient
  // would be 10⁴ m/s. Then positions at 100 Hz of a pair at rest, some with 1 cm jumps.
  VelocityFilterOptions o = optionsOf(2, 20.0);
  RelativeVelocityFilter filter(o);
  Eigen::VectorXd state;
  filter.update(0.0, Eigen::Vector3d(1, 0, 0), &state);
  filter.update(0.01, Eigen::Vector3d(1, 0, 0), &state);
  const double t0 = 0.01 + 2.0 * o.max_gap;
  EXPECT_EQ(filter.update(t0, Eigen::Vector3d(1, 0, 0), &state), VelocityFilterVerdict::kStarted);
  EXPECT_NE(filter.update(t0 + 1e-6, Eigen::Vector3d(1.01, 0, 0), &state),
            VelocityFilterVerdict::kEstimated);
  double largest = 0.0;
  int estimates = 0;
  for (int k = 1; k <= 100; ++k) {
    const double jump = (k % 7 == 0) ? 0.01 : 0.0;
    if (filter.update(t0 + 0.01 * k, Eigen::Vector3d(1 + jump, 0, 0), &state) ==
        VelocityFilterVerdict::kEstimated) {
      ++estimates;
      largest = std::max(largest, state.tail(2).norm());
    }
  }
  EXPECT_EQ(estimates, 100);
  EXPECT_LE(largest, o.max_speed);
  EXPECT_LT(largest, 2.0);  // 1 cm over 10 ms at most, filtered
}

TEST(RelativeVelocityFilter, NoEstimateBeyondMaxSpeedLeavesTheFilter) {
  VelocityFilterOptions o = optionsOf(2, 20.0);
  o.max_speed = 10.0;
  RelativeVelocityFilter filter(o);
  Eigen::VectorXd state;
  // The start's difference quotient: 20 m/s.
  filter.update(0.0, Eigen::Vector3d(0, 0, 0), &state);
  EXPECT_EQ(filter.update(0.01, Eigen::Vector3d(0.2, 0, 0), &state),
            VelocityFilterVerdict::kTooFast);
  // Started again from that position: 5 m/s from it is estimated.
  ASSERT_EQ(filter.update(0.02, Eigen::Vector3d(0.2, 0.05, 0), &state),
            VelocityFilterVerdict::kEstimated);
  EXPECT_NEAR(state(3), 5.0, 1e-9);
  // The α-β update: a 2 m jump of one position drives v̂ to 5 + 2 (1 − θ)²/Δt = 11.6 m/s.
  EXPECT_EQ(filter.update(0.03, Eigen::Vector3d(0.2, 2.1, 0), &state),
            VelocityFilterVerdict::kTooFast);
  // The glitch is where it started from: the next true position is too fast from it as well.
  EXPECT_EQ(filter.update(0.04, Eigen::Vector3d(0.2, 0.15, 0), &state),
            VelocityFilterVerdict::kTooFast);
  ASSERT_EQ(filter.update(0.05, Eigen::Vector3d(0.2, 0.2, 0), &state),
            VelocityFilterVerdict::kEstimated);
  EXPECT_NEAR(state(3), 5.0, 1e-9);
  // A plausible change of the velocity is still estimated.
  ASSERT_EQ(filter.update(0.06, Eigen::Vector3d(0.3, 0.2, 0), &state),
            VelocityFilterVerdict::kEstimated);
  EXPECT_LE(state.tail(2).norm(), o.max_speed);
}

}  // namespace
}  // namespace projection_collision_avoidance
