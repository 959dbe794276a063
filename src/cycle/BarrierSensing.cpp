#include "projection_collision_avoidance/cycle/BarrierSensing.hpp"

#include <algorithm>
#include <cstring>

namespace projection_collision_avoidance {
namespace {

constexpr char kTargetId[] = "target";

}  // namespace

BarrierSensing::BarrierSensing(int dimension) : filter_(dimension), dimension_(dimension) {}

const SafetyFilter& BarrierSensing::sense(
    const GenericDimensions::StateVector& relative_state,
    const Eigen::Ref<const Eigen::VectorXd>* target_acceleration, double target_perimeter,
    double rate, const NeighbourSensing* neighbours, const NeighbourSample* sample,
    double neighbour_acceleration) {
  const int k = dimension_;
  filter_.clear();
  Eigen::Vector3d p = Eigen::Vector3d::Zero();
  Eigen::Vector3d v = Eigen::Vector3d::Zero();
  Eigen::Vector3d a = Eigen::Vector3d::Zero();
  p.head(k) = -relative_state.head(k);
  v.head(k) = -relative_state.segment(k, k);
  if (target_acceleration != nullptr && target_acceleration->size() >= k) {
    a.head(k) = target_acceleration->head(k);
  }
  const BarrierConstraint target = exponentialBarrier(p, v, a, target_perimeter, rate);
  target_barrier_ = target.barrier;
  if (filter_.add(target)) {
    sources_[0] = -1;
  }
  if (neighbours == nullptr || sample == nullptr) {
    return filter_;
  }
  const NeighbourConstraints& kept = neighbours->constraints();
  for (int j = 0; j < kept.kept(); ++j) {
    const int source = kept.constraint(j).source;
    if (source < 0 || source >= sample->count ||
        sample->agents[static_cast<std::size_t>(source)].target) {
      continue;  // the target's barrier is the first
    }
    const NeighbourMark& mark = neighbours->mark(source);
    p.setZero();
    v.setZero();
    a.setZero();
    p.head(k) = -mark.position.head(k);
    v.head(k) = -sample->agents[static_cast<std::size_t>(source)].velocity.head(k);
    const double distance = p.norm();
    if (distance > 0.0) {
      a = (neighbour_acceleration / distance) * p;  // the worst case: toward the follower
    }
    const int index = filter_.size();
    if (filter_.add(exponentialBarrier(p, v, a, mark.perimeter, rate))) {
      sources_[static_cast<std::size_t>(index)] = source;
    }
  }
  return filter_;
}

void BarrierSensing::report(const DynamicFollowerStatus& status, const NeighbourSample* sample,
                            BarrierReport* report) const {
  report->configured = true;
  report->given = true;
  report->barriers = filter_.size();
  report->active = status.constraints_active;
  report->dropped = status.constraints_dropped;
  report->projected = status.command_projected;
  report->infeasible = status.barrier_infeasible;
  report->target_barrier = target_barrier_;
  report->binding = -1;
  report->binding_id[0] = '\0';
  const int index = status.binding_barrier;
  if (index < 0 || index >= filter_.size()) {
    return;
  }
  const int source = sources_[static_cast<std::size_t>(index)];
  if (source < 0) {
    report->binding = 0;
    std::copy_n(kTargetId, sizeof(kTargetId), report->binding_id.begin());
  } else if (sample != nullptr && source < sample->count) {
    report->binding = source + 1;
    report->binding_id = sample->agents[static_cast<std::size_t>(source)].id;
  }
}

}  // namespace projection_collision_avoidance
