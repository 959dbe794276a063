#pragma once

#include <ostream>

#include "projection_collision_avoidance/sim/SampledSimulator.hpp"
#include "projection_collision_avoidance/sim/Scenario.hpp"

namespace projection_collision_avoidance {

/// Writes a run as CSV: a header row on construction, then one row per control tick with the
/// columns of README.md, "Scenario files" (t, xi_*, xi_hat_*, norms, bounds, f, projection_active,
/// positions, velocities for double integrators, separation, perimeter, u_*, u_baseline_*,
/// u_tracker_*, leader_u_*, ud_*); with turning slots (formation.slots: turning) then
/// slot_heading, slot_yaw_rate, slot_yaw_acceleration (theta, theta', theta'' of (T1)),
/// slot_p_* (the turned slot's position part R(theta) d_p, (T2)) and u_slot_* (u_r, (T3)); with
/// path slots (formation.slots: path) slot_p_* (D's position part, p_target − r), u_slot_* (u_r
/// = r''), ref_p_* (r), goal_p_* (q), progress (s), goal_arc (sigma*), chord (||p_target −
/// r||) and braking (1 when the barrier (C5) bounds r''), (C1)-(C5).
class SimulationCsvWriter {
 public:
  SimulationCsvWriter(std::ostream& out, const Scenario& scenario);
  void write(const SimulationSample& sample);

 private:
  std::ostream& out_;
  int states_;
  int inputs_;
  int positions_;
  bool velocities_;
  bool turning_;
  bool path_;
  bool neighbours_;  // formation.neighbours: the projection's columns
  double xi_max_;
  double xi_soft_;
  double perimeter_;
};

}  // namespace projection_collision_avoidance
