#pragma once

#include <functional>
#include <string>

#include <Eigen/Core>

#include "projection_collision_avoidance/Scenario.hpp"

namespace projection_collision_avoidance {

/// One control tick of a simulated run, as written to the CSV.
struct SimulationSample {
  double time = 0.0;               ///< t_k (s)
  Eigen::VectorXd relative_error;  ///< xi = x_1 - x_2 - d
  Eigen::VectorXd estimate;        ///< xi_hat used at t_k
  double constraint_value = 0.0;   ///< f(xi_hat)
  bool projection_active = false;
  Eigen::VectorXd leader_state;      ///< x_1
  Eigen::VectorXd follower_state;    ///< x_2
  double separation = 0.0;           ///< ||p_1 - p_2|| (m)
  Eigen::VectorXd command;           ///< u_2
  Eigen::VectorXd baseline_command;  ///< G y
  Eigen::VectorXd tracker_command;   ///< u_a
  Eigen::VectorXd leader_input;      ///< u_1(t_k)
  Eigen::VectorXd disturbance;       ///< u_d(t_k)
};

/// The figures of a run; norms are taken at the control ticks.
struct SimulationSummary {
  double max_xi = 0.0;                   ///< max ||xi|| (m)
  double max_xi_hat = 0.0;               ///< max ||xi_hat|| (m)
  double xi_max = 0.0;                   ///< (1 - alpha) ||d|| (m)
  double perimeter = 0.0;                ///< alpha ||d|| (m)
  double min_separation = 0.0;           ///< min ||p_1 - p_2|| (m)
  double time_outside = 0.0;             ///< time with ||xi|| > xi_max (s)
  double max_boundary_correction = 0.0;  ///< largest RK4 excess removed by the estimator (m)
  long ticks = 0;                        ///< control ticks simulated
};

/// Called once per control tick, in time order.
using SampleObserver = std::function<void(const SimulationSample&)>;

/// Runs the closed loop of a scenario without ROS: at each tick t_k = k / control_rate, for
/// k = 0 .. round(duration * control_rate), the follower steps on y_k = C (x_1 - x_2 - d); then
/// both agents are integrated exactly to t_{k+1}, inputs held, the step split at disturbance
/// pulse edges. Throws ParameterError for an invalid scenario.
SimulationSummary simulate(const Scenario& scenario, const SampleObserver& observer = {});

/// The summary line "max_xi=.. max_xi_hat=.. xi_max=.. min_separation=.. time_outside=..
/// wall_s=.." (values in %.9g), with @p wall_seconds the run's wall-clock time.
std::string formatSummary(const SimulationSummary& summary, double wall_seconds);

}  // namespace projection_collision_avoidance
