#pragma once

/// @file
/// One follower of SampledSimulator's run (its controller, plant, true vehicle and figures) and
/// what it senses of the other agents each tick: the neighbours' half-spaces (N3) and the barrier
/// filter's barriers (B2). Private to src/sim.

#include <cmath>
#include <limits>
#include <optional>
#include <vector>

#include <Eigen/Core>

#include "projection_collision_avoidance/core/ControllerDesign.hpp"
#include "projection_collision_avoidance/core/ConvoyReference.hpp"
#include "projection_collision_avoidance/core/FollowerController.hpp"
#include "projection_collision_avoidance/core/NeighbourBarrier.hpp"
#include "projection_collision_avoidance/core/SafetyFilter.hpp"
#include "projection_collision_avoidance/core/TurningSlot.hpp"
#include "projection_collision_avoidance/sim/AgentIntegrator.hpp"
#include "projection_collision_avoidance/sim/SampledSimulator.hpp"
#include "projection_collision_avoidance/sim/VehicleResponse.hpp"

namespace projection_collision_avoidance {
namespace sim_detail {

/// One follower of the run: its controller, its plant and its figures.
template <typename Dims>
struct SimulatedFollower {
  /// @param turning the slot heading's generator of turning slots; null for world slots
  /// @param path the convoy's parameters of path slots and @p target_state its target's initial
  /// state; null for other slots
  SimulatedFollower(const FormationMember& formation_member, const ControllerDesign& member_design,
                    const AgentModel& model, const SlotHeadingParameters* turning,
                    const ConvoyParameters* path, const Eigen::VectorXd& target_state,
                    const WorldSpec& world, double duration, const NeighbourParameters* neighbours,
                    double perimeter)
      : member(formation_member),
        design(member_design),
        controller(member_design),
        plant(model, member_design.period, formation_member.initial_state,
              world.disturbanceOf(formation_member.index, model, duration)),
        separation(formation_member.separation),
        command(Dims::InputVector::Zero(model.inputDimension())) {
    if (turning) {
      heading.emplace(*turning, member_design.period);
      heading->reset(formation_member.initial_heading);
    }
    if (path) {
      const int k = model.position_dimension;
      convoy.emplace(*path, member_design.period, separation.head(k).norm());
      Eigen::Vector3d position = Eigen::Vector3d::Zero();
      Eigen::Vector3d velocity = Eigen::Vector3d::Zero();
      position.head(k) = target_state.head(k);
      velocity.head(k) = target_state.segment(k, k);
      convoy->reset(position, velocity, formation_member.path_direction);
    }
    if (neighbours) {
      constraints.emplace(*neighbours, perimeter, model.position_dimension,
                          member_design.parameters.acceleration_limit);
    }
    if (member_design.parameters.safety_filter) {
      barriers.emplace(model.position_dimension);
      summary.barrier_filter = true;
    }
    const VehicleSpec& true_vehicle = world.vehicleOf(member.index);
    if (world.configured && !true_vehicle.ideal()) {
      vehicle.emplace(true_vehicle, member_design.period, model.inputDimension());
    }
    summary.xi_max = design.xi_max;
    summary.perimeter = design.perimeter;
    summary.min_separation = std::numeric_limits<double>::infinity();
  }

  FormationMember member;
  ControllerDesign design;
  FollowerController<Dims> controller;
  AgentIntegrator<Dims> plant;
  typename Dims::StateVector separation;  // d_i
  typename Dims::InputVector command;     // u_i at the current tick
  std::optional<SlotHeading> heading;     // theta_i (T1) of a turning slot
  std::optional<ConvoyReference> convoy;  // r_i (C1)-(C3) of a path slot
  std::optional<VehicleResponse<typename Dims::InputVector>> vehicle;  // a true vehicle apart
  std::optional<NeighbourConstraints> constraints;  // (N3) with formation.neighbours
  std::optional<SafetyFilter> barriers;             // (B3) with controller.safety_filter
  SimulationSummary summary;
};

/// (N3): follower @p self's sensed agents this tick, every agent but itself (the leader's state
/// @p leader, the followers' plants), exact relative states; its target with the perimeter of its
/// design, alpha ||d_i||.
template <typename Dims>
void senseNeighbours(SimulatedFollower<Dims>& self, const typename Dims::StateVector& leader,
                     const std::vector<SimulatedFollower<Dims>>& followers, int k) {
  NeighbourConstraints& constraints = *self.constraints;
  constraints.clear();
  const auto& own = self.plant.state();
  auto add = [&](const typename Dims::StateVector& other, int index) {
    Eigen::Vector3d p = Eigen::Vector3d::Zero();
    Eigen::Vector3d v = Eigen::Vector3d::Zero();
    for (int e = 0; e < k; ++e) {
      p(e) = own(e) - other(e);
      v(e) = own(k + e) - other(k + e);
    }
    constraints.add(p, v,
                    index == self.member.target ? self.design.perimeter : constraints.perimeter());
  };
  add(leader, 0);
  for (const SimulatedFollower<Dims>& other : followers) {
    if (other.member.index != self.member.index) {
      add(other.plant.state(), other.member.index);
    }
  }
}

/// The agent of a NeighbourConstraint's `source` in senseNeighbours()'s order: 0 the leader
/// (null), s >= 1 the s-th follower other than @p self.
template <typename Dims>
const SimulatedFollower<Dims>* sensedFollower(const SimulatedFollower<Dims>& self,
                                              const std::vector<SimulatedFollower<Dims>>& followers,
                                              int source) {
  int seen = 0;
  for (const SimulatedFollower<Dims>& other : followers) {
    if (other.member.index != self.member.index && ++seen == source) {
      return &other;
    }
  }
  return nullptr;
}

/// (B2): follower @p self's barriers this tick, exact relative states, the most urgent first.
/// First its target's, perimeter alpha ||d_i||, with the target's acceleration
/// @p target_acceleration when the leader's input is shared (@p target_known), 0 otherwise. Then,
/// with formation.neighbours, the other agents senseNeighbours() kept, in its order (radius,
/// max_neighbours, (N1)'s urgency), each at its worst allowed acceleration, A_n =
/// @p neighbour_acceleration toward the follower (p^T a_j = A_n ||p||), perimeter rho.
template <typename Dims>
void senseBarriers(SimulatedFollower<Dims>& self, const typename Dims::StateVector& leader,
                   const std::vector<SimulatedFollower<Dims>>& followers,
                   const Eigen::Vector3d& target_acceleration, bool target_known,
                   double neighbour_acceleration, int k) {
  SafetyFilter& barriers = *self.barriers;
  barriers.clear();
  const double rate = self.design.parameters.safety_filter->rate;
  const auto& own = self.plant.state();
  auto add = [&](const typename Dims::StateVector& other, bool is_target, double perimeter) {
    Eigen::Vector3d p = Eigen::Vector3d::Zero();
    Eigen::Vector3d v = Eigen::Vector3d::Zero();
    for (int e = 0; e < k; ++e) {
      p(e) = own(e) - other(e);
      v(e) = own(k + e) - other(k + e);
    }
    Eigen::Vector3d a = Eigen::Vector3d::Zero();
    if (is_target) {
      a = target_known ? target_acceleration : a;
    } else if (p.norm() > 0.0) {
      a = neighbour_acceleration * p.normalized();
    }
    barriers.add(exponentialBarrier(p, v, a, perimeter, rate));
  };
  const SimulatedFollower<Dims>* target =
      self.member.target == 0 ? nullptr
                              : &followers[static_cast<std::size_t>(self.member.target - 1)];
  add(target == nullptr ? leader : target->plant.state(), true, self.design.perimeter);
  if (!self.constraints) {
    return;
  }
  const NeighbourConstraints& sensed = *self.constraints;
  for (int j = 0; j < sensed.kept(); ++j) {
    const SimulatedFollower<Dims>* other =
        sensedFollower(self, followers, sensed.constraint(j).source);
    if (other != target) {
      add(other == nullptr ? leader : other->plant.state(), false, sensed.perimeter());
    }
  }
}

}  // namespace sim_detail
}  // namespace projection_collision_avoidance
