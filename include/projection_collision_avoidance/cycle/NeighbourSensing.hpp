#pragma once

#include <array>
#include <cstdint>

#include <Eigen/Core>

#include "projection_collision_avoidance/core/CommandProjection.hpp"
#include "projection_collision_avoidance/core/FollowerControllerStatus.hpp"
#include "projection_collision_avoidance/core/NeighbourBarrier.hpp"
#include "projection_collision_avoidance/cycle/LatchedInputs.hpp"

namespace projection_collision_avoidance {

/// formation.neighbours as the control cycle runs it: the parameters and rho.
struct NeighbourCycleSettings {
  NeighbourParameters parameters;  ///< validated (FormationSpec::validateNeighbours())
  double perimeter = 1.0;          ///< rho (m): formation.neighbours.perimeter, or alpha ||d||
};

/// What became of one sensed agent at a step.
enum class NeighbourRole : std::uint8_t {
  kSensed = 0,   ///< within the message, but not constraining (beyond the radius, harmless, or
                 ///< less urgent than max_neighbours others)
  kKept = 1,     ///< its half-space was given to the command and holds with room
  kBinding = 2,  ///< its half-space holds with equality at the command: it acts
  kDropped = 3,  ///< its half-space could not be met with the more urgent ones and the limit
};

/// One sensed agent as the step used it (for the markers).
struct NeighbourMark {
  Eigen::Vector3d position = Eigen::Vector3d::Zero();  ///< p_j - p_i at the step's stamp (m)
  double perimeter = 0.0;                              ///< the perimeter kept around it (m)
  NeighbourRole role = NeighbourRole::kSensed;
};

/// What the neighbours did at a step. Fixed size: filling it allocates nothing.
struct NeighbourReport {
  bool configured = false;        ///< formation.neighbours is on
  bool fresh = false;             ///< the step had a neighbour array younger than the timeout
  double age = 0.0;               ///< s, of the latest accepted array at the stamp; +inf: none
  int sent = 0;                   ///< agents in that array
  int sensed = 0;                 ///< of the agents used (the nearest 64), within the radius
  int kept = 0;                   ///< half-spaces given to the command (at most max_neighbours)
  int active = 0;                 ///< of them, holding with equality at the command
  int dropped = 0;                ///< of them, dropped: they could not all be met (N3)
  bool projected = false;         ///< the half-spaces moved the command
  double nearest = 0.0;           ///< m, the nearest sensed agent; +inf: none
  double smallest_barrier = 0.0;  ///< h (m/s) of the most urgent kept one; -inf inside; +inf
  int binding = -1;               ///< the most urgent agent whose half-space acts; -1: none
  std::array<char, SensedAgent::kIdLength> binding_id{};  ///< its id; "" when none
  int count = 0;                                          ///< marks[0 .. count)
  std::array<NeighbourMark, NeighbourSample::kCapacity> marks;
};

/// The neighbours' half-spaces (N1)-(N3) of each control step, from the latest accepted
/// neighbour array: each agent moved to the step's stamp at constant relative velocity, given
/// its perimeter (the target's alpha ||d_i||, the others' rho), and afterwards what each one did.
/// Allocates nothing after construction.
class NeighbourSensing {
 public:
  /// @param settings the parameters and rho, @param dimension k = 1, 2 or 3
  /// @param acceleration_limit a_max (m/s^2) of the design at start
  NeighbourSensing(const NeighbourCycleSettings& settings, int dimension,
                   double acceleration_limit);

  /// The half-spaces for a step stamped @p ahead s after @p sample's stamp (|ahead| is held
  /// within @p horizon s), the target's perimeter @p target_perimeter (m): p_i - p_j =
  /// -(position + velocity ahead), v_i - v_j = -velocity.
  const CommandProjection& constrain(const NeighbourSample& sample, double ahead, double horizon,
                                     double target_perimeter);
  /// What the constraints of the last constrain() did to the step's command (@p status), into
  /// @p report (whose fresh and age the caller fills), with the agents' ids from @p sample.
  void report(const NeighbourSample& sample, const DynamicFollowerStatus& status,
              NeighbourReport* report) const;
  /// The half-spaces of the last constrain(): the kept ones, most urgent first.
  const NeighbourConstraints& constraints() const { return constraints_; }
  /// Agent @p j (< the sample's count) of the last constrain(), at the step's stamp.
  const NeighbourMark& mark(int j) const { return marks_[static_cast<std::size_t>(j)]; }

 private:
  NeighbourConstraints constraints_;
  int dimension_;
  double perimeter_;
  std::array<NeighbourMark, NeighbourSample::kCapacity> marks_;  ///< of the last constrain()
  int count_ = 0;
};

}  // namespace projection_collision_avoidance
