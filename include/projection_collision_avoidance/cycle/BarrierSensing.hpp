#pragma once

#include <array>

#include <Eigen/Core>

#include "projection_collision_avoidance/core/FollowerControllerStatus.hpp"
#include "projection_collision_avoidance/core/SafetyFilter.hpp"
#include "projection_collision_avoidance/core/TypeDefs.hpp"
#include "projection_collision_avoidance/cycle/LatchedInputs.hpp"
#include "projection_collision_avoidance/cycle/NeighbourSensing.hpp"

namespace projection_collision_avoidance {

/// What the barrier filter (controller.safety_filter, (B1)-(B3)) did at a step. Fixed size:
/// filling it allocates nothing.
struct BarrierReport {
  bool configured = false;  ///< controller.safety_filter is on
  bool given = false;       ///< the step's command was filtered (a measured step)
  int barriers = 0;         ///< barriers given: the target's, then the kept neighbours'
  int active = 0;           ///< of them, holding with equality at the command
  int dropped = 0;          ///< of them, left out: they and the limit could not all be met
  bool projected = false;   ///< the filter moved the command
  bool infeasible = false;  ///< the barriers and acceleration_limit could not all be met
  /// The most urgent barrier holding with equality: 0 the target's, j >= 1 the neighbour array's
  /// agent j - 1; -1: none
  int binding = -1;
  std::array<char, SensedAgent::kIdLength> binding_id{};  ///< "target", the agent's id, or ""
  double target_barrier = 0.0;  ///< h = ||p||^2 - rho^2 of the target (m^2) (B1)
};

/// The barriers (B2) of each control step of the follower node: first its target's from the
/// measured relative state x_target - x_i (p_i - p_j = -its positions, v_i - v_j = -its
/// velocities), with the target's acceleration when the leader broadcast gives it (else 0);
/// then, with formation.neighbours, every other agent NeighbourSensing kept, at its position at
/// the step's stamp and at its worst allowed acceleration, A_n toward the follower (as cf_sim).
/// Allocates nothing after construction.
class BarrierSensing {
 public:
  /// @param dimension k = 1, 2 or 3
  explicit BarrierSensing(int dimension);

  /// The barriers of a step: @p relative_state x_target - x_i (m, m/s; 2k entries),
  /// @p target_acceleration its acceleration (m/s^2, k entries) or null when unknown,
  /// @p target_perimeter alpha ||d_i|| (m), @p rate lambda (1/s); @p neighbours and @p sample
  /// the step's constrain()ed neighbours (null without formation.neighbours), each other agent at
  /// acceleration @p neighbour_acceleration A_n (m/s^2) toward the follower.
  const SafetyFilter& sense(const GenericDimensions::StateVector& relative_state,
                            const Eigen::Ref<const Eigen::VectorXd>* target_acceleration,
                            double target_perimeter, double rate,
                            const NeighbourSensing* neighbours, const NeighbourSample* sample,
                            double neighbour_acceleration);
  /// What the barriers of the last sense() did to the step's command (@p status) into
  /// @p report, the agents' ids from @p sample (null without formation.neighbours).
  void report(const DynamicFollowerStatus& status, const NeighbourSample* sample,
              BarrierReport* report) const;

 private:
  SafetyFilter filter_;
  int dimension_;
  double target_barrier_ = 0.0;
  /// The agent of each barrier the filter holds: -1 the target, else the neighbour array's index.
  std::array<int, CommandProjection::kMaxConstraints> sources_{};
};

}  // namespace projection_collision_avoidance
