#pragma once

#include <functional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "projection_collision_avoidance/core/ConvoyReference.hpp"
#include "projection_collision_avoidance/core/FollowerControllerStatus.hpp"
#include "projection_collision_avoidance/core/TurningSlot.hpp"
#include "projection_collision_avoidance/sim/Scenario.hpp"

namespace projection_collision_avoidance {

/// One control tick of one follower of a simulated run, as written to the CSV. In a formation
/// "leader" is the follower's target (the leader or the follower ahead of it).
struct SimulationSample {
  double time = 0.0;               ///< t_k (s)
  Eigen::VectorXd relative_error;  ///< xi = x_1 - x_2 - d
  Eigen::VectorXd leader_state;    ///< x_1
  Eigen::VectorXd follower_state;  ///< x_2
  double distance = 0.0;           ///< ||p_1 - p_2|| (m)
  /// The slot heading theta, theta' and theta'' of a turning slot (T1) (rad, rad/s, rad/s^2);
  /// 0 for a world slot.
  SlotHeadingSample slot_heading;
  Eigen::VectorXd slot;  ///< D = x_1 - x_2 on the slot: d, d turned by theta (T2), or (C4)
  /// A path slot's reference r, its goal q and the chord (C1)-(C4); zero for other slots.
  ConvoySample convoy;
  Eigen::VectorXd leader_input;  ///< the target's acceleration input (u_1(t_k) for the leader)
  Eigen::VectorXd disturbance;   ///< the target's disturbance (u_d(t_k) for the leader, else 0)
  /// The controller's status at t_k, the one type the nodes publish (estimate, f, projection,
  /// command and its parts); the continuous loop fills the fields it has.
  DynamicFollowerStatus controller;
};

/// The figures of a run; norms are taken at the control ticks.
struct SimulationSummary {
  double max_xi = 0.0;                   ///< max ||xi|| (m)
  double max_xi_hat = 0.0;               ///< max ||xi_hat|| (m)
  double xi_max = 0.0;                   ///< (1 - alpha) ||d|| (m)
  double perimeter = 0.0;                ///< alpha ||d|| (m)
  double min_separation = 0.0;           ///< min ||p_1 - p_2|| (m), to the target in a formation
  double time_outside = 0.0;             ///< time with ||xi|| > xi_max (s)
  double max_boundary_correction = 0.0;  ///< largest RK4 excess removed by the estimator (m)
  long ticks = 0;                        ///< control ticks simulated
  /// With controller.safety_filter (barrier_filter): ticks the barrier (B2) moved the command,
  /// and ticks it and the acceleration limit could not both be met (B3).
  bool barrier_filter = false;
  long barrier_ticks = 0;
  long barrier_infeasible_ticks = 0;
};

/// The figures of a formation's run.
struct FormationSummary {
  std::vector<SimulationSummary> followers;  ///< follower i at i - 1, against its own target
  std::vector<int> targets;  ///< target of follower i at i - 1: 0 the leader, j follower j
  /// min ||p_a - p_b|| over every pair of agents, the leader included (m): pairs that are not
  /// leader and follower of each other are not protected by the method, only reported.
  double min_pair_separation = 0.0;
  /// rho (m): every agent's perimeter for the pairs' figures, the paper's alpha ||d|| of the
  /// scenario's d
  double perimeter = 0.0;
  /// min ||p_a - p_b|| over the pairs of which neither looks at the other (neighbours, m);
  /// infinity when there is none
  double min_neighbour_separation = 0.0;
  /// The pairs of agents (any two) that came closer than rho at some tick.
  int pairs_inside_perimeter = 0;
  /// Of those, the pairs of which neither looks at the other.
  int neighbour_pairs_inside_perimeter = 0;
};

/// Called once per control tick, in time order.
using SampleObserver = std::function<void(const SimulationSample&)>;
/// Called once per control tick and follower (follower i as @p member = i - 1), in time order.
using FormationObserver = std::function<void(int member, const SimulationSample&)>;

/// Runs the closed loop of a scenario's formation without ROS: at each tick t_k = k /
/// control_rate, for k = 0 .. round(duration * control_rate), every follower i in index order
/// steps on y_i = C (x_target - x_i - d_i); then every agent is integrated exactly to t_{k+1},
/// inputs held, the leader's step split at disturbance pulse edges. With turning slots
/// (formation.slots: turning) follower i's slot is D_i (T2), turned by its slot heading (T1),
/// which follows the heading of its target's velocity, and it is given u_r (T3); with path slots
/// (formation.slots: path) it tracks its reference point on its target's path (C1)-(C3), D_i and
/// u_r of (C4), with no shared acceleration of its target. Each follower is
/// given its own state x_i for the time headway (S1). With leader information
/// (controller.leader_information) a follower of the leader is given a_1 = u_1(t_k) (+ pinv(B)
/// u_d(t_k) when the disturbance is shared), and a follower of follower j the command follower j
/// computed at the same tick; with a link section, these values as the link delivers them instead
/// ((L1)-(L3): delayed by D periods, lost with probability dropout, the last one held). Throws
/// ParameterError for an invalid scenario.
FormationSummary simulateFormation(const Scenario& scenario,
                                   const FormationObserver& observer = {});

/// simulateFormation() for a scenario of one follower (the paper's pair); throws
/// ParameterError("formation.followers") for more.
SimulationSummary simulate(const Scenario& scenario, const SampleObserver& observer = {});

/// The summary line "max_xi=.. max_xi_hat=.. xi_max=.. min_separation=.. time_outside=..
/// wall_s=.." (values in %.9g), with @p wall_seconds the run's wall-clock time; with the barrier
/// filter, " barrier_ticks=.. barrier_infeasible_ticks=.." after it.
std::string formatSummary(const SimulationSummary& summary, double wall_seconds);

}  // namespace projection_collision_avoidance
