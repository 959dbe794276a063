/// AgentIntegrator: exact zero-order-hold steps of a double integrator against closed-form
/// solutions, with disturbance pulses whose edges fall on a tick or inside a step.

#include <cmath>
#include <stdexcept>
#include <utility>

#include <Eigen/Core>
#include <gtest/gtest.h>

#include "projection_collision_avoidance/core/AgentModel.hpp"
#include "projection_collision_avoidance/sim/AgentIntegrator.hpp"
#include "projection_collision_avoidance/sim/SignalProfile.hpp"

#include "EigenTestHelpers.hpp"

namespace projection_collision_avoidance {
namespace {

/// p'' = a on one axis with x' = [v + w_p; a]: the state [p; v] after @p dt with a, w_p constant.
Eigen::Vector2d closedForm(const Eigen::Vector2d& x, double acceleration, double position_rate,
                           double dt) {
  return {x(0) + (x(1) + position_rate) * dt + 0.5 * acceleration * dt * dt,
          x(1) + acceleration * dt};
}

SignalProfile pulse(double start, double end, const Eigen::VectorXd& vector) {
  SignalProfile profile;
  profile.pulses.push_back(Pulse{start, end, vector});
  return profile;
}

TEST(AgentIntegrator, HeldInputMatchesTheClosedForm) {
  const double dt = 0.37;
  AgentIntegrator<DoubleIntegrator1D> agent(makeDoubleIntegrator(1), dt,
                                            Eigen::Vector2d(1.5, -0.4));
  Eigen::Vector2d expected(1.5, -0.4);
  for (int k = 0; k < 50; ++k) {
    const double u = std::sin(0.3 * k);
    agent.advance(k * dt, Eigen::Matrix<double, 1, 1>(u));
    expected = closedForm(expected, u, 0.0, dt);
    ASSERT_MATRIX_NEAR(agent.state(), expected, 1e-11);
  }
}

TEST(AgentIntegrator, StepOfAnotherLengthAndZeroStep) {
  AgentIntegrator<DoubleIntegrator1D> agent(makeDoubleIntegrator(1), 0.01,
                                            Eigen::Vector2d(0.0, 2.0));
  agent.advance(0.0, 1.25, Eigen::Matrix<double, 1, 1>(-0.8));
  EXPECT_MATRIX_NEAR(agent.state(), closedForm(Eigen::Vector2d(0.0, 2.0), -0.8, 0.0, 1.25), 1e-12);
  const Eigen::Vector2d before = agent.state();
  agent.advance(1.25, 0.0, Eigen::Matrix<double, 1, 1>(5.0));
  EXPECT_MATRIX_NEAR(agent.state(), before, 0.0);
  EXPECT_THROW(agent.advance(1.25, -0.1, Eigen::Matrix<double, 1, 1>(0.0)), std::invalid_argument);
}

TEST(AgentIntegrator, PulseEdgesOnTicksActOverWholeSteps) {
  // Pulse [1.0, 2.0) with dt = 0.5: the edges are ticks, so each step is either fully in or out.
  const Eigen::Vector2d w(-2.0, -3.0);
  AgentIntegrator<DoubleIntegrator1D> agent(makeDoubleIntegrator(1), 0.5, Eigen::Vector2d::Zero(),
                                            pulse(1.0, 2.0, w));
  Eigen::Vector2d expected = Eigen::Vector2d::Zero();
  for (int k = 0; k < 6; ++k) {
    const double t = 0.5 * k;
    const bool on = t >= 1.0 && t < 2.0;
    agent.advance(t, Eigen::Matrix<double, 1, 1>(1.0));
    expected = closedForm(expected, 1.0 + (on ? w(1) : 0.0), on ? w(0) : 0.0, 0.5);
    ASSERT_MATRIX_NEAR(agent.state(), expected, 1e-12) << "step " << k;
  }
}

TEST(AgentIntegrator, PulseEdgeInsideAStepSplitsIt) {
  // Step [0, 1] with u = 0.5; the pulse starts at 0.3 inside it.
  const Eigen::Vector2d w(0.7, -1.2);
  const double u = 0.5;
  AgentIntegrator<DoubleIntegrator1D> agent(makeDoubleIntegrator(1), 1.0, Eigen::Vector2d(2.0, 1.0),
                                            pulse(0.3, 10.0, w));
  agent.advance(0.0, Eigen::Matrix<double, 1, 1>(u));
  const Eigen::Vector2d at_edge = closedForm(Eigen::Vector2d(2.0, 1.0), u, 0.0, 0.3);
  const Eigen::Vector2d expected = closedForm(at_edge, u + w(1), w(0), 0.7);
  EXPECT_MATRIX_NEAR(agent.state(), expected, 1e-12);
  // Unsplit, the pulse would have acted over the whole step or not at all.
  EXPECT_GT((agent.state() - closedForm(Eigen::Vector2d(2.0, 1.0), u, 0.0, 1.0)).norm(), 0.1);
  EXPECT_GT((agent.state() - closedForm(Eigen::Vector2d(2.0, 1.0), u + w(1), w(0), 1.0)).norm(),
            0.1);
}

TEST(AgentIntegrator, PulseStartingAndEndingInsideOneStep) {
  // Step [2, 3]; the pulse covers [2.25, 2.6): three segments.
  const Eigen::Vector2d w(-0.4, 3.0);
  const double u = -1.0;
  const Eigen::Vector2d x0(-1.0, 0.5);
  AgentIntegrator<DoubleIntegrator1D> agent(makeDoubleIntegrator(1), 1.0, x0, pulse(2.25, 2.6, w));
  agent.advance(2.0, Eigen::Matrix<double, 1, 1>(u));
  Eigen::Vector2d expected = closedForm(x0, u, 0.0, 0.25);
  expected = closedForm(expected, u + w(1), w(0), 0.35);
  expected = closedForm(expected, u, 0.0, 0.4);
  EXPECT_MATRIX_NEAR(agent.state(), expected, 1e-12);
}

TEST(AgentIntegrator, PaperDisturbanceWithEdgesBetweenTicks) {
  // The paper's u_d = [-2, -2] for 20 <= t < 23 on a resting leader at 5 m, steps of 0.3 s (the
  // edges 20 and 23 fall inside steps). Closed form: v drops by 2 m/s per s over the pulse to
  // -6 m/s; p gains the integral of v - 2 over the pulse, -15 m, then moves at -6 m/s.
  const double dt = 0.3;
  AgentIntegrator<DoubleIntegrator1D> agent(makeDoubleIntegrator(1), dt, Eigen::Vector2d(5.0, 0.0),
                                            pulse(20.0, 23.0, Eigen::Vector2d(-2.0, -2.0)));
  for (int k = 0; k < 66; ++k) {  // to 19.8 s
    agent.advance(k * dt, Eigen::Matrix<double, 1, 1>(0.0));
  }
  EXPECT_MATRIX_NEAR(agent.state(), Eigen::Vector2d(5.0, 0.0), 0.0);
  agent.advance(66 * dt, Eigen::Matrix<double, 1, 1>(0.0));  // [19.8, 20.1]: 0.1 s of pulse
  EXPECT_MATRIX_NEAR(agent.state(), closedForm(Eigen::Vector2d(5.0, 0.0), -2.0, -2.0, 0.1), 1e-12);
  for (int k = 67; k < 200; ++k) {
    agent.advance(k * dt, Eigen::Matrix<double, 1, 1>(0.0));
  }
  const double t = 200 * dt;  // 60 s
  EXPECT_MATRIX_NEAR(agent.state(), Eigen::Vector2d(5.0 - 15.0 - 6.0 * (t - 23.0), -6.0), 1e-9);
}

TEST(AgentIntegrator, PlanarDoubleIntegratorFixedAndGenericAgree) {
  const AgentModel model = makeDoubleIntegrator(2);
  const Eigen::Vector4d x0(1.0, -2.0, 0.5, 0.25);
  const Eigen::Vector4d w(0.1, 0.2, -0.3, 0.4);
  AgentIntegrator<DoubleIntegrator2D> fixed(model, 0.2, x0, pulse(0.45, 0.9, w));
  AgentIntegrator<GenericDimensions> generic(model, 0.2, x0, pulse(0.45, 0.9, w));
  const Eigen::Vector2d u(0.6, -0.9);
  Eigen::Vector2d px(x0(0), x0(2));
  Eigen::Vector2d py(x0(1), x0(3));
  for (int k = 0; k < 10; ++k) {
    fixed.advance(0.2 * k, u);
    generic.advance(0.2 * k, GenericDimensions::InputVector(u));
  }
  // Per axis: 0.45 s without, 0.45 s with the pulse, 1.1 s without (total 2 s).
  for (const auto& [axis, state] : {std::pair<int, Eigen::Vector2d*>{0, &px}, {1, &py}}) {
    *state = closedForm(*state, u(axis), 0.0, 0.45);
    *state = closedForm(*state, u(axis) + w(2 + axis), w(axis), 0.45);
    *state = closedForm(*state, u(axis), 0.0, 1.1);
  }
  const Eigen::Vector4d expected(px(0), py(0), px(1), py(1));
  EXPECT_MATRIX_NEAR(fixed.state(), expected, 1e-11);
  EXPECT_MATRIX_NEAR(generic.state(), expected, 1e-11);
  EXPECT_MATRIX_NEAR(generic.disturbanceAt(0.5), w, 0.0);
  EXPECT_TRUE(generic.disturbanceAt(0.9).isZero());
}

TEST(AgentIntegrator, RefusesSizesThatDoNotFit) {
  const AgentModel planar = makeDoubleIntegrator(2);
  EXPECT_THROW(AgentIntegrator<DoubleIntegrator1D>(planar, 0.1, Eigen::Vector4d::Zero()),
               std::invalid_argument);
  EXPECT_THROW(AgentIntegrator<GenericDimensions>(planar, 0.1, Eigen::Vector2d::Zero()),
               std::invalid_argument);
  EXPECT_THROW(AgentIntegrator<GenericDimensions>(planar, 0.0, Eigen::Vector4d::Zero()),
               std::invalid_argument);
  EXPECT_THROW(AgentIntegrator<GenericDimensions>(planar, 0.1, Eigen::Vector4d::Zero(),
                                                  pulse(0.0, 1.0, Eigen::Vector2d::Ones())),
               std::invalid_argument);
  AgentIntegrator<GenericDimensions> agent(planar, 0.1, Eigen::Vector4d::Zero());
  EXPECT_THROW(agent.setState(Eigen::Vector2d::Zero()), std::invalid_argument);
  agent.setState(Eigen::Vector4d::Ones());
  EXPECT_MATRIX_NEAR(agent.state(), Eigen::Vector4d::Ones(), 0.0);
  EXPECT_DOUBLE_EQ(agent.nominalStep(), 0.1);
}

}  // namespace
}  // namespace projection_collision_avoidance
