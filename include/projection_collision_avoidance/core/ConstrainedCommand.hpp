#pragma once

#include <Eigen/Core>

#include "projection_collision_avoidance/core/CommandProjection.hpp"
#include "projection_collision_avoidance/core/CommandRateLimiter.hpp"
#include "projection_collision_avoidance/core/FollowerControllerStatus.hpp"
#include "projection_collision_avoidance/core/SafetyFilter.hpp"

namespace projection_collision_avoidance {

/// The last stage of FollowerController's command: the neighbours' half-spaces (N3) or the
/// barrier filter (B3), after sat() and the rate limit. Works on the step's status in place.
template <typename Dims>
class ConstrainedCommand {
 public:
  using InputVector = typename Dims::InputVector;

  /// @param acceleration_limit a_max (m/s^2), > 0 or infinity: kept by both constraints
  explicit ConstrainedCommand(double acceleration_limit)
      : acceleration_limit_(acceleration_limit) {}

  /// status->command constrained by @p filter when given (B3: u* of the barriers and the limit),
  /// else by @p constraints (N3: the projection onto the half-spaces and the limit, the less
  /// urgent dropped when they cannot all be met); either may be null or of another dimension
  /// than the command (then nothing is done). The constrained command becomes the rate limit's
  /// previous one, and status's constraint fields say what acted. True when it moved the command.
  bool apply(const CommandProjection* constraints, const SafetyFilter* filter,
             FollowerControllerStatus<Dims>* status,
             CommandRateLimiter<InputVector>* rate_limiter) const {
    status->command_projected = false;
    status->constraints_given = 0;
    status->constraints_active = 0;
    status->constraints_dropped = 0;
    status->binding_barrier = -1;
    status->barrier_infeasible = false;
    const Eigen::Index m = status->command.size();
    if (filter != nullptr) {
      if (filter->size() == 0 || m > 3 || filter->problem().dimension() != m) {
        return false;
      }
      const SafetyFilterResult result =
          filter->filter(padded(status->command), acceleration_limit_);
      status->binding_barrier = result.active;
      status->barrier_infeasible = result.infeasible;
      return adopt(result.command, result.changed, filter->size(), result.active_count,
                   result.dropped, status, rate_limiter);
    }
    if (constraints == nullptr || constraints->size() == 0 || m > 3 ||
        constraints->dimension() != m) {
      return false;
    }
    const CommandProjectionResult result =
        constraints->project(padded(status->command), acceleration_limit_);
    return adopt(result.command, result.changed, constraints->size(), result.active, result.dropped,
                 status, rate_limiter);
  }

 private:
  /// @p command (at most 3 entries) in 3 entries, 0 beyond its size.
  static Eigen::Vector3d padded(const InputVector& command) {
    Eigen::Vector3d out = Eigen::Vector3d::Zero();
    out.head(command.size()) = command;
    return out;
  }

  /// The counts into @p status and, when @p changed, the first entries of @p command as the
  /// step's command and the rate limit's previous one. Returns @p changed.
  static bool adopt(const Eigen::Vector3d& command, bool changed, int given, int active,
                    int dropped, FollowerControllerStatus<Dims>* status,
                    CommandRateLimiter<InputVector>* rate_limiter) {
    status->constraints_given = given;
    status->constraints_active = active;
    status->constraints_dropped = dropped;
    if (changed) {
      status->command = command.head(status->command.size());
      rate_limiter->setPrevious(status->command);
      status->command_projected = true;
    }
    return changed;
  }

  double acceleration_limit_;
};

}  // namespace projection_collision_avoidance
