#include "projection_collision_avoidance/cycle/NeighbourSensing.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace projection_collision_avoidance {
namespace {

/// Relative slack within which a kept half-space counts as holding with equality (binding).
constexpr double kBindingTolerance = 1e-6;

}  // namespace

NeighbourSensing::NeighbourSensing(const NeighbourCycleSettings& settings, int dimension,
                                   double acceleration_limit)
    : constraints_(settings.parameters, settings.perimeter, dimension, acceleration_limit),
      dimension_(dimension),
      perimeter_(settings.perimeter) {}

const CommandProjection& NeighbourSensing::constrain(const NeighbourSample& sample, double ahead,
                                                     double horizon, double target_perimeter) {
  const double dt = std::clamp(std::isfinite(ahead) ? ahead : 0.0, -horizon, horizon);
  constraints_.clear();
  count_ = std::clamp(sample.count, 0, NeighbourSample::kCapacity);
  for (int j = 0; j < count_; ++j) {
    const SensedAgent& agent = sample.agents[static_cast<std::size_t>(j)];
    NeighbourMark& mark = marks_[static_cast<std::size_t>(j)];
    mark.position.setZero();
    mark.position.head(dimension_) =
        agent.position.head(dimension_) + dt * agent.velocity.head(dimension_);
    mark.perimeter = agent.target ? target_perimeter : perimeter_;
    mark.role = NeighbourRole::kSensed;
    Eigen::Vector3d velocity = Eigen::Vector3d::Zero();
    velocity.head(dimension_) = -agent.velocity.head(dimension_);
    constraints_.add(-mark.position, velocity, mark.perimeter);  // (N1)-(N2) of p_i - p_j
  }
  return constraints_.projection();
}

void NeighbourSensing::report(const NeighbourSample& sample, const DynamicFollowerStatus& status,
                              NeighbourReport* report) const {
  report->configured = true;
  report->sent = sample.sent;
  report->sensed = constraints_.sensed();
  report->kept = status.constraints_given;
  report->active = status.constraints_active;
  report->dropped = status.constraints_dropped;
  report->projected = status.command_projected;
  report->nearest = constraints_.nearest();
  report->smallest_barrier = constraints_.smallestBarrier();
  report->binding = -1;
  report->binding_id[0] = '\0';
  report->count = count_;
  std::copy_n(marks_.begin(), count_, report->marks.begin());
  const Eigen::Index m = status.command.size();
  if (status.constraints_given == 0 || m > 3 || m != dimension_) {
    return;  // none given (a step without the half-spaces)
  }
  Eigen::Vector3d command = Eigen::Vector3d::Zero();
  command.head(m) = status.command;
  for (int j = 0; j < constraints_.kept(); ++j) {
    const NeighbourConstraint& constraint = constraints_.constraint(j);
    const double slack = constraint.normal.dot(command) - constraint.bound;
    const double scale = std::max({1.0, std::abs(constraint.bound), command.norm()});
    NeighbourRole role = NeighbourRole::kKept;
    if (slack < -kBindingTolerance * scale) {
      role = NeighbourRole::kDropped;
    } else if (status.command_projected && slack <= kBindingTolerance * scale) {
      role = NeighbourRole::kBinding;
      if (report->binding < 0) {  // the most urgent one that acts
        report->binding = constraint.source;
        report->binding_id = sample.agents[static_cast<std::size_t>(constraint.source)].id;
      }
    }
    report->marks[static_cast<std::size_t>(constraint.source)].role = role;
  }
}

}  // namespace projection_collision_avoidance
