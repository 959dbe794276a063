#include "projection_collision_avoidance/core/Formation.hpp"

#include <cmath>
#include <cstddef>

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
}

std::vector<FormationMember> layoutFormation(const FormationSpec& spec,
                                             const Eigen::VectorXd& separation,
                                             const Eigen::VectorXd& leader_initial_state,
                                             const Eigen::VectorXd& follower_initial_state) {
  const Eigen::VectorXd initial_error = leader_initial_state - follower_initial_state - separation;
  std::vector<FormationMember> members;
  members.reserve(static_cast<std::size_t>(spec.followers));
  for (int i = 1; i <= spec.followers; ++i) {
    FormationMember member;
    member.index = i;
    member.name = spec.configured ? "follower_" + std::to_string(i) : "follower";
    const bool chain = spec.topology == FormationTopology::kChain;
    if (spec.shape == FormationShape::kLine) {
      member.target = chain ? i - 1 : 0;
      member.separation = chain ? separation : Eigen::VectorXd(static_cast<double>(i) * separation);
    } else {
      const int rank = (i + 1) / 2;
      const double angle = i % 2 == 1 ? spec.half_angle : -spec.half_angle;
      const Eigen::VectorXd arm = turnedInPlane(separation, angle);
      member.target = chain ? (i > 2 ? i - 2 : 0) : 0;
      member.separation = chain ? arm : Eigen::VectorXd(static_cast<double>(rank) * arm);
    }
    const Eigen::VectorXd& target_state =
        member.target == 0 ? leader_initial_state
                           : members[static_cast<std::size_t>(member.target - 1)].initial_state;
    member.target_name =
        member.target == 0 ? "leader" : members[static_cast<std::size_t>(member.target - 1)].name;
    member.initial_state = target_state - member.separation - initial_error;
    members.push_back(member);
  }
  return members;
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

}  // namespace projection_collision_avoidance
