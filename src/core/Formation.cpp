#include "projection_collision_avoidance/core/Formation.hpp"

#include <cmath>
#include <cstddef>

#include "projection_collision_avoidance/core/FollowerConfiguration.hpp"
#include "projection_collision_avoidance/core/ParameterError.hpp"

namespace projection_collision_avoidance {
namespace {

constexpr double kHalfPi = 1.5707963267948966;

/// d with its position part turned by @p angle (rad) in the x-y plane.
Eigen::VectorXd turnedInPlane(const Eigen::VectorXd& separation, double angle) {
  Eigen::VectorXd turned = separation;
  const double c = std::cos(angle);
  const double s = std::sin(angle);
  turned(0) = c * separation(0) - s * separation(1);
  turned(1) = s * separation(0) + c * separation(1);
  return turned;
}

}  // namespace

void FormationSpec::validate(const AgentModel& model) const {
  if (followers < 1 || followers > kMaxFollowers) {
    throw ParameterError("formation.followers", "must lie in [1, " + std::to_string(kMaxFollowers) +
                                                    "], got " + std::to_string(followers));
  }
  if (shape == FormationShape::kV) {
    const int axes = model.double_integrator_axes;
    if (axes != 2 && axes != 3) {
      throw ParameterError("formation.shape",
                           "v needs a double_integrator model of 2 or 3 axes (its arms lie in "
                           "the x-y plane); use line");
    }
    if (!(half_angle > 0.0 && half_angle < kHalfPi)) {
      throw ParameterError("formation.half_angle",
                           "must lie in (0, pi/2) rad, got " + std::to_string(half_angle));
    }
  }
  if (slots == SlotFrame::kTurning) {
    const int axes = model.double_integrator_axes;
    if (axes != 2 && axes != 3) {
      throw ParameterError("formation.slots",
                           "turning needs a double_integrator model of 2 or 3 axes (slots turn "
                           "about z); use world");
    }
    turning.validate("formation.turning");
  }
  if (slots == SlotFrame::kPath) {
    const int axes = model.double_integrator_axes;
    if (axes < 1 || axes > 3) {
      throw ParameterError("formation.slots",
                           "path needs a double_integrator model of 1 to 3 axes; use world");
    }
    if (shape != FormationShape::kLine) {
      throw ParameterError("formation.slots",
                           "path puts every follower on its target's path: use shape line");
    }
    path.validate("formation.path");
  }
}

void FormationSpec::validateConvoy(const ControllerParameters& controller) const {
  if (slots != SlotFrame::kPath) {
    return;
  }
  if (controller.leader_input_in_command || controller.leader_input_in_estimator) {
    throw ParameterError(controller.leader_input_in_command
                             ? "controller.leader_information.command"
                             : "controller.leader_information.estimator",
                         "must be false with formation.slots: path (a convoy follower tracks its "
                         "own reference point, not its target's acceleration)");
  }
  if (controller.time_headway > 0.0) {
    throw ParameterError("controller.spacing.time_headway",
                         "must be 0 with formation.slots: path (the arc gap sets the spacing)");
  }
}

void FormationSpec::validateNeighbours(const ControllerParameters& controller) const {
  if (!neighbours.enabled) {
    return;
  }
  const int axes = controller.model.double_integrator_axes;
  if (axes < 1 || axes > 3) {
    throw ParameterError("formation.neighbours",
                         "needs a double integrator of 1 to 3 axes (model.type, model.dimension)");
  }
  neighbours.validate(controller.acceleration_limit);
}

FormationMember formationSlot(const FormationSpec& spec, const Eigen::VectorXd& separation,
                              int index) {
  FormationMember member;
  member.index = index;
  member.name = spec.configured ? "follower_" + std::to_string(index) : "follower";
  const bool chain = spec.topology == FormationTopology::kChain;
  if (spec.shape == FormationShape::kLine) {
    member.target = chain ? index - 1 : 0;
    member.separation =
        chain ? separation : Eigen::VectorXd(static_cast<double>(index) * separation);
  } else {
    const int rank = (index + 1) / 2;
    const double angle = index % 2 == 1 ? spec.half_angle : -spec.half_angle;
    const Eigen::VectorXd arm = turnedInPlane(separation, angle);
    member.target = chain ? (index > 2 ? index - 2 : 0) : 0;
    member.separation = chain ? arm : Eigen::VectorXd(static_cast<double>(rank) * arm);
  }
  member.target_name = member.target == 0 ? std::string("leader")
                                          : formationSlot(spec, separation, member.target).name;
  return member;
}

std::vector<FormationMember> layoutFormation(const FormationSpec& spec,
                                             const Eigen::VectorXd& separation,
                                             const Eigen::VectorXd& leader_initial_state,
                                             const Eigen::VectorXd& follower_initial_state) {
  const Eigen::VectorXd initial_error = leader_initial_state - follower_initial_state - separation;
  std::vector<FormationMember> members;
  members.reserve(static_cast<std::size_t>(spec.followers));
  for (int i = 1; i <= spec.followers; ++i) {
    FormationMember member = formationSlot(spec, separation, i);
    const Eigen::VectorXd& target_state =
        member.target == 0 ? leader_initial_state
                           : members[static_cast<std::size_t>(member.target - 1)].initial_state;
    Eigen::VectorXd slot = member.separation;
    if (spec.slots == SlotFrame::kTurning) {
      const int axes = static_cast<int>(target_state.size() / 2);
      member.initial_heading =
          velocityHeading(target_state(axes), target_state(axes + 1), spec.turning.min_speed)
              .value_or(0.0);
      turningSlotOffset(member.separation, axes, SlotHeadingSample{member.initial_heading, 0, 0},
                        &slot);
    }
    if (spec.slots == SlotFrame::kPath) {
      const int axes = static_cast<int>(target_state.size() / 2);
      member.path_direction.head(axes) = member.separation.head(axes).normalized();
      ConvoyReference reference(spec.path, 1.0, member.separation.head(axes).norm());
      Eigen::Vector3d position = Eigen::Vector3d::Zero();
      Eigen::Vector3d velocity = Eigen::Vector3d::Zero();
      position.head(axes) = target_state.head(axes);
      velocity.head(axes) = target_state.segment(axes, axes);
      reference.reset(position, velocity, member.path_direction);
      const ConvoySample start = reference.tick(position, velocity);
      convoySlotOffset(target_state, axes, start, &slot);
    }
    member.initial_state = target_state - slot - initial_error;
    members.push_back(member);
  }
  return members;
}

FormationMember FollowerConfiguration::member(int index, const std::string& index_key) const {
  if (index < 1 || index > formation.followers) {
    throw ParameterError(index_key, "is " + std::to_string(index) + " but the formation has " +
                                        std::to_string(formation.followers) + " follower(s)");
  }
  return formationSlot(formation, controller.separation, index);
}

ControllerParameters memberParameters(const ControllerParameters& parameters,
                                      const FormationMember& member) {
  ControllerParameters result = parameters;
  result.separation = member.separation;
  return result;
}

std::string toString(FormationTopology topology) {
  return topology == FormationTopology::kChain ? "chain" : "star";
}

std::string toString(FormationShape shape) { return shape == FormationShape::kV ? "v" : "line"; }

std::string toString(SlotFrame frame) {
  return frame == SlotFrame::kTurning ? "turning" : frame == SlotFrame::kPath ? "path" : "world";
}

FormationTopology parseFormationTopology(const std::string& text, const std::string& key) {
  if (text == "star") {
    return FormationTopology::kStar;
  }
  if (text == "chain") {
    return FormationTopology::kChain;
  }
  throw ParameterError(key, "must be star or chain, got '" + text + "'");
}

FormationShape parseFormationShape(const std::string& text, const std::string& key) {
  if (text == "line") {
    return FormationShape::kLine;
  }
  if (text == "v") {
    return FormationShape::kV;
  }
  throw ParameterError(key, "must be line or v, got '" + text + "'");
}

SlotFrame parseSlotFrame(const std::string& text, const std::string& key) {
  if (text == "world") {
    return SlotFrame::kWorld;
  }
  if (text == "turning") {
    return SlotFrame::kTurning;
  }
  if (text == "path") {
    return SlotFrame::kPath;
  }
  throw ParameterError(key, "must be world, turning or path, got '" + text + "'");
}

}  // namespace projection_collision_avoidance
