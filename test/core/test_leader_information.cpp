/// Leader information: the leader's acceleration a_1 = u_1 + pinv(B) u_d fed forward into the
/// command and the estimator, and what it cannot do about the position-rate part of u_d.

#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "projection_collision_avoidance/core/ControllerDesign.hpp"
#include "projection_collision_avoidance/core/ParameterError.hpp"
#include "projection_collision_avoidance/scenario/ScenarioLoader.hpp"
#include "projection_collision_avoidance/sim/SampledSimulator.hpp"

#include "EigenTestHelpers.hpp"
#include "TestScenarios.hpp"

namespace projection_collision_avoidance {
namespace {

using testing::paperParameters;
using testing::scenarioPath;

SimulationSummary run(const std::string& disturbance, const std::vector<std::string>& sharing) {
  std::vector<std::string> overrides = {"controller.control_rate=100",
                                        "leader.disturbance.0.vector=" + disturbance};
  overrides.insert(overrides.end(), sharing.begin(), sharing.end());
  return simulate(loadScenarioFile(scenarioPath("paper_run2.yaml"), overrides));
}

const std::vector<std::string> kNone = {};
const std::vector<std::string> kCommand = {"controller.leader_information.command=true",
                                           "controller.leader_information.disturbance=true"};
const std::vector<std::string> kEstimator = {"controller.leader_information.estimator=true",
                                             "controller.leader_information.disturbance=true"};
const std::vector<std::string> kBoth = {"controller.leader_information.command=true",
                                        "controller.leader_information.estimator=true",
                                        "controller.leader_information.disturbance=true"};

TEST(LeaderAcceleration, AddsTheAccelerationPartOfTheDisturbance) {
  ControllerParameters p = paperParameters();
  p.leader_input_in_command = true;
  const Eigen::VectorXd u1 = Eigen::VectorXd::Constant(1, 0.5);
  const Eigen::Vector2d ud(-2.0, -3.0);  // m/s, m/s^2
  EXPECT_MATRIX_NEAR(ControllerDesign::create(p).leaderAcceleration(u1, ud), u1, 0.0);
  p.leader_disturbance_shared = true;
  const ControllerDesign design = ControllerDesign::create(p);
  EXPECT_MATRIX_NEAR(design.leaderAcceleration(u1, ud), Eigen::VectorXd::Constant(1, -2.5), 1e-15);
  EXPECT_MATRIX_NEAR(design.leaderAcceleration(u1, Eigen::VectorXd()), u1, 0.0);  // unknown u_d
  // The 3-D double integrator: the velocity-rate half of u_d.
  ControllerParameters p3 = p;
  p3.model = makeDoubleIntegrator(3);
  p3.separation = Eigen::VectorXd::Zero(6);
  p3.separation(0) = 5.0;
  p3.baseline_gain =
      doubleIntegratorGain(Eigen::Vector3d::Ones(), Eigen::Vector3d::Constant(0.7), "g");
  p3.tracker_gain =
      doubleIntegratorGain(Eigen::Vector3d::Constant(3.0), Eigen::Vector3d::Ones(), "g");
  p3.reference_gain = Eigen::MatrixXd::Zero(3, 6);
  p3.estimator_gain = -5.0 * Eigen::MatrixXd::Identity(6, 6);
  p3.lyapunov_weight = Eigen::MatrixXd::Identity(6, 6);
  Eigen::VectorXd ud3(6);
  ud3 << 1.0, 2.0, 3.0, 4.0, 5.0, 6.0;
  EXPECT_MATRIX_NEAR(ControllerDesign::create(p3).leaderAcceleration(Eigen::Vector3d::Zero(), ud3),
                     Eigen::Vector3d(4.0, 5.0, 6.0), 1e-14);
}

TEST(LeaderAcceleration, RefusesASharedDisturbanceThatGoesNowhere) {
  ControllerParameters p = paperParameters();
  p.leader_disturbance_shared = true;
  try {
    ControllerDesign::create(p);
    FAIL() << "accepted";
  } catch (const ParameterError& error) {
    EXPECT_EQ(error.key(), "controller.leader_information.disturbance");
  }
}

TEST(LeaderInformation, CommandFeedForwardCancelsAnAccelerationDisturbance) {
  // u_d = [0, -2] m/s^2 over [20, 23) s, on the ticks: fed forward, the follower accelerates
  // with the leader, and xi stays zero.
  for (const bool tracker : {false, true}) {
    std::vector<std::string> shared = kCommand;
    shared.push_back(std::string("controller.tracker.enabled=") + (tracker ? "true" : "false"));
    EXPECT_LT(run("[0.0, -2.0]", shared).max_xi, 1e-9) << tracker;
    std::vector<std::string> blind = {shared.back()};
    EXPECT_GT(run("[0.0, -2.0]", blind).max_xi, 0.1) << tracker;
  }
}

TEST(LeaderInformation, NoSharingModeChangesAPositionRateDisturbance) {
  // u_d = [-2, 0] m/s is outside the range of B: its acceleration part is zero, so every sharing
  // mode gives the follower nothing, and the run is the unshared one to the last bit.
  const SimulationSummary none = run("[-2.0, 0.0]", kNone);
  EXPECT_GT(none.max_xi, 1.0);
  for (const auto& sharing : {kCommand, kEstimator, kBoth}) {
    const SimulationSummary shared = run("[-2.0, 0.0]", sharing);
    EXPECT_EQ(shared.max_xi, none.max_xi);
    EXPECT_EQ(shared.min_separation, none.min_separation);
  }
}

TEST(LeaderInformation, TheCommandRemovesOnlyTheAccelerationPartOfAMixedDisturbance) {
  // The paper's u_d = [-2, -2]: with the acceleration part fed forward, what remains is the run
  // of the position-rate part alone.
  const SimulationSummary shared = run("[-2.0, -2.0]", kCommand);
  const SimulationSummary position_part = run("[-2.0, 0.0]", kNone);
  EXPECT_NEAR(shared.max_xi, position_part.max_xi, 1e-9);
  EXPECT_LT(shared.max_xi, run("[-2.0, -2.0]", kNone).max_xi);
}

TEST(LeaderInformation, TheEstimatorModelTracksTheAccelerationPartWithoutCancellingIt) {
  // Shared into the estimator only, a_1 makes xi_hat follow xi through the pulse, so the tracker
  // (which acts on y - y_hat) no longer sees it: the follower is not pulled back, and the
  // estimate error stays small.
  const SimulationSummary estimator = run("[0.0, -2.0]", kEstimator);
  const SimulationSummary none = run("[0.0, -2.0]", kNone);
  EXPECT_GT(estimator.max_xi, 1.0);
  EXPECT_NE(estimator.max_xi, none.max_xi);
  EXPECT_LE(estimator.max_xi_hat, estimator.xi_max + 1e-12);
}

}  // namespace
}  // namespace projection_collision_avoidance
