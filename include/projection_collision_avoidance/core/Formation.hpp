#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

#include "projection_collision_avoidance/core/AgentModel.hpp"
#include "projection_collision_avoidance/core/ControllerParameters.hpp"
#include "projection_collision_avoidance/core/ConvoyReference.hpp"
#include "projection_collision_avoidance/core/NeighbourBarrier.hpp"
#include "projection_collision_avoidance/core/TurningSlot.hpp"

namespace projection_collision_avoidance {

/// Who a follower looks at.
enum class FormationTopology {
  kStar,   ///< every follower looks at the leader, with its own separation d_i
  kChain,  ///< every follower looks at the agent ahead of it
};

/// Where the slots lie.
enum class FormationShape {
  kLine,  ///< behind one another along the scenario's d
  kV,     ///< two arms, d turned by +half_angle (odd followers) and -half_angle (even ones)
};

/// The frame the slots d_i are given in (formation.slots).
enum class SlotFrame {
  kWorld,    ///< fixed in the world, as the paper's d: the formation translates, never turns
  kTurning,  ///< in the target's body frame, turned with the slot heading theta (T1)-(T3)
  kPath,     ///< a convoy: on the target's path, an arc gap behind it (C1)-(C4)
};

/// The followers of a scenario (section `formation` of a scenario file). Without that section a
/// scenario has one follower, named "follower", on the scenario's d: the paper's pair.
struct FormationSpec {
  bool configured = false;  ///< the scenario has a formation section
  int followers = 1;        ///< N, 1 .. kMaxFollowers
  FormationTopology topology = FormationTopology::kStar;
  FormationShape shape = FormationShape::kLine;
  double half_angle = 0.5235987755982988;  ///< rad, angle of each arm of a V to d (30 deg)
  SlotFrame slots = SlotFrame::kWorld;     ///< formation.slots
  SlotHeadingParameters turning;           ///< formation.turning (slots: turning)
  ConvoyParameters path;                   ///< formation.path (slots: path)
  NeighbourParameters neighbours;          ///< formation.neighbours (N1)-(N3)

  static constexpr int kMaxFollowers = 1000;

  /// Throws ParameterError naming formation.followers / .shape / .half_angle for a count out of
  /// range, a V on a model that is not a double integrator of 2 or 3 axes, or an angle outside
  /// (0, pi/2); formation.slots for turning slots on such a model, or path slots on a model
  /// that is not a double integrator or in a V; formation.turning.* for a bad generator
  /// (SlotHeadingParameters::validate()); formation.path.* (ConvoyParameters::validate()).
  void validate(const AgentModel& model) const;
  /// With path slots: throws ParameterError naming the keys of the controller's shared leader
  /// input and time headway when they are on (a convoy follower tracks its own reference point:
  /// doc/math.md, (C4)).
  void validateConvoy(const ControllerParameters& controller) const;
  /// With formation.neighbours: throws ParameterError naming formation.neighbours (a model that
  /// is not a double integrator of 1 to 3 axes) or formation.neighbours.* (a value out of range,
  /// NeighbourParameters::validate() against controller.acceleration_limit).
  void validateNeighbours(const ControllerParameters& controller) const;
};

/// One follower of a formation, with everything that differs from one follower to the next.
struct FormationMember {
  std::string name;  ///< "follower" (no formation section) or "follower_<i>"; also its tf frame
  int index = 1;     ///< i, 1 .. N
  int target = 0;    ///< the agent it looks at: 0 the leader, j in 1 .. i-1 follower j
  std::string target_name;  ///< "leader" or the name of follower j
  /// d_i: x_target - x_i on the slot (in ker A); with turning slots, in the target's body frame
  /// (the world's at theta = 0)
  Eigen::VectorXd separation;
  /// theta(0) of a turning slot (rad): the heading of the target's initial velocity
  /// (velocityHeading()), 0 when it has none; 0 for world slots.
  double initial_heading = 0.0;
  /// Path slots: the unit direction of d_i's position part (3 entries), the target's path's
  /// initial direction (C1); zero otherwise.
  Eigen::Vector3d path_direction = Eigen::Vector3d::Zero();
  /// x_i(0) = x_target(0) - D_i - xi_0 (D_i = d_i, or turned by theta(0) (T2)), with xi_0 = x_1(0)
  /// - x_2(0) - d the scenario's initial relative error, so that every follower starts as the
  /// scenario's single follower does.
  Eigen::VectorXd initial_state;
};

/// Follower @p index (1 .. spec.followers) of a formation: its name, target and slot d_i, as
/// layoutFormation() lays them out (initial_state left empty).
FormationMember formationSlot(const FormationSpec& spec, const Eigen::VectorXd& separation,
                              int index);

/// The followers of a formation in index order (every target precedes its follower).
///
/// With turning slots, follower i starts on its slot turned by theta_i(0) (initial_heading);
/// with path slots, on its reference point's initial state (ConvoyReference::reset()).
/// With d the scenario's separation, r_i = ceil(i / 2) and R(+-theta) the rotation of the
/// position part about the z axis (the x-y plane) by the V's half angle theta, sign + for odd i:
///   star, line:   d_i = i d,                target 0
///   chain, line:  d_i = d,                  target i - 1
///   star, V:      d_i = r_i R(+-theta) d,   target 0
///   chain, V:     d_i = R(+-theta) d,       target max(0, i - 2)
/// @param spec a validated formation
/// @param separation d (n entries, in ker A)
/// @param leader_initial_state x_1(0)
/// @param follower_initial_state the scenario's x_2(0), which fixes xi_0
std::vector<FormationMember> layoutFormation(const FormationSpec& spec,
                                             const Eigen::VectorXd& separation,
                                             const Eigen::VectorXd& leader_initial_state,
                                             const Eigen::VectorXd& follower_initial_state);

/// The controller parameters of one member: @p parameters with separation d_i.
ControllerParameters memberParameters(const ControllerParameters& parameters,
                                      const FormationMember& member);

/// "star", "chain"; "line", "v"; "world", "turning", "path".
std::string toString(FormationTopology topology);
std::string toString(FormationShape shape);
std::string toString(SlotFrame frame);

/// Parses "star" / "chain" and "line" / "v"; throws ParameterError(key) otherwise.
FormationTopology parseFormationTopology(const std::string& text, const std::string& key);
FormationShape parseFormationShape(const std::string& text, const std::string& key);
/// Parses "world" / "turning" / "path"; throws ParameterError(key) otherwise.
SlotFrame parseSlotFrame(const std::string& text, const std::string& key);

}  // namespace projection_collision_avoidance
