#pragma once

#include <array>
#include <cstdint>

#include <Eigen/Core>

#include "projection_collision_avoidance/core/TypeDefs.hpp"
#include "projection_collision_avoidance/cycle/InputTimeline.hpp"
#include "projection_collision_avoidance/rt/LatestValue.hpp"

namespace projection_collision_avoidance {

/// One accepted relative measurement, as the input side hands it to the control cycle.
struct MeasurementSample {
  std::int64_t stamp_ns = 0;    ///< its header stamp (ns since the epoch)
  std::int64_t receipt_ns = 0;  ///< ROS time when it was accepted (ns)
  std::uint64_t sequence = 0;   ///< measurements accepted so far, this one included
  GenericDimensions::StateVector relative_state;  ///< x_target - x_i (m, m/s)
};

/// One accepted leader broadcast: the target's acceleration as the follower uses it.
struct LeaderSample {
  std::int64_t stamp_ns = 0;
  std::int64_t receipt_ns = 0;
  std::uint64_t sequence = 0;
  GenericDimensions::InputVector acceleration;  ///< a_target (m/s^2)
};

/// One accepted odometry of the follower itself: its own state, from which a time headway acts.
struct OwnStateSample {
  std::int64_t stamp_ns = 0;
  std::int64_t receipt_ns = 0;
  std::uint64_t sequence = 0;
  GenericDimensions::StateVector state;  ///< x_i (m, m/s)
  /// The velocity of the follower's controlled point, the point the relative measurement is of
  /// (the origin's, or a look-ahead point's) (m/s, one entry per axis): with the measured relative
  /// velocity, the target's (turning and path slots).
  GenericDimensions::InputVector controlled_velocity;
  /// The controlled point's position (m, one entry per axis): with the measured relative
  /// position, the target's (path slots).
  GenericDimensions::InputVector controlled_position;
};

/// One agent of an accepted NeighbourArray: its state relative to the follower.
struct SensedAgent {
  static constexpr std::size_t kIdLength =
      32;  ///< id characters kept, the terminating NUL included
  Eigen::Vector3d position = Eigen::Vector3d::Zero();  ///< p_j - p_i (m; entries beyond k are 0)
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();  ///< v_j - v_i (m/s)
  bool target = false;                                 ///< its id is the follower's target's
  std::array<char, kIdLength> id{};  ///< its id, NUL-terminated (a longer one cut short)
};

/// One accepted neighbour array (`neighbours`): the nearest sensed agents, nearest first.
struct NeighbourSample {
  static constexpr int kCapacity = 64;  ///< agents kept of one message, the nearest
  std::int64_t stamp_ns = 0;
  std::int64_t receipt_ns = 0;
  std::uint64_t sequence = 0;
  int count = 0;  ///< agents in agents[0 .. count)
  int sent = 0;   ///< agents the message held (count = min(sent, kCapacity))
  std::array<SensedAgent, kCapacity> agents;
};

/// The follower's input slots, lock-free triple buffers (LatestValue) that the input callbacks
/// write and the control cycle latches, and which of the latched inputs belong to the timeline
/// of the cycle's ROS time: an input received after it is one of an old timeline (ROS time went
/// back) and not valid. Allocates nothing after construction.
class LatchedInputs {
 public:
  /// The slot the measurement callback writes (one writer thread).
  LatestValue<MeasurementSample>& measurementSlot() { return measurement_; }
  /// The slot the leader-broadcast callback writes (one writer thread).
  LatestValue<LeaderSample>& leaderSlot() { return leader_; }
  /// The slot the own odometry's callback writes (one writer thread; time headway only).
  LatestValue<OwnStateSample>& ownStateSlot() { return own_state_; }
  /// The slot the neighbour array's callback writes (one writer thread; formation.neighbours).
  LatestValue<NeighbourSample>& neighbourSlot() { return neighbours_; }

  /// Reads the latest inputs from their slots (the cycle's thread).
  void latch() {
    ever_measured_ = measurement_.read() || ever_measured_;
    ever_led_ = leader_.read() || ever_led_;
    ever_own_state_ = own_state_.read() || ever_own_state_;
    ever_neighbours_ = neighbours_.read() || ever_neighbours_;
  }
  /// Which latched inputs are of this timeline at ROS time @p now_ns (received at or before it).
  void checkTimeline(std::int64_t now_ns) {
    have_measurement_ = ever_measured_ && measurement_.value().receipt_ns <= now_ns;
    have_leader_ = ever_led_ && leader_.value().receipt_ns <= now_ns;
    have_own_state_ = ever_own_state_ && own_state_.value().receipt_ns <= now_ns;
    have_neighbours_ = ever_neighbours_ && neighbours_.value().receipt_ns <= now_ns;
  }

  const MeasurementSample& measurement() const { return measurement_.value(); }
  const LeaderSample& leader() const { return leader_.value(); }
  const OwnStateSample& ownState() const { return own_state_.value(); }
  const NeighbourSample& neighbours() const { return neighbours_.value(); }
  bool haveMeasurement() const { return have_measurement_; }  ///< valid on this timeline
  bool everMeasured() const { return ever_measured_; }        ///< accepted since start
  bool haveLeader() const { return have_leader_; }
  bool everLed() const { return ever_led_; }
  bool haveOwnState() const { return have_own_state_; }
  bool haveNeighbours() const { return have_neighbours_; }
  bool everNeighboured() const { return ever_neighbours_; }

  /// Ages (s) at @p at_ns of the latched measurement / leader broadcast / own state / neighbours
  /// (inputAge()); kNoInputAge when none is valid on this timeline.
  double measurementAge(std::int64_t at_ns) const {
    return have_measurement_ ? ageOf(measurement_.value(), at_ns) : kNoInputAge;
  }
  double leaderAge(std::int64_t at_ns) const {
    return have_leader_ ? ageOf(leader_.value(), at_ns) : kNoInputAge;
  }
  double ownStateAge(std::int64_t at_ns) const {
    return have_own_state_ ? ageOf(own_state_.value(), at_ns) : kNoInputAge;
  }
  double neighboursAge(std::int64_t at_ns) const {
    return have_neighbours_ ? ageOf(neighbours_.value(), at_ns) : kNoInputAge;
  }

 private:
  template <typename Sample>
  static double ageOf(const Sample& sample, std::int64_t at_ns) {
    return inputAge(at_ns, sample.stamp_ns, sample.receipt_ns);
  }

  LatestValue<MeasurementSample> measurement_;
  LatestValue<LeaderSample> leader_;
  LatestValue<OwnStateSample> own_state_;
  LatestValue<NeighbourSample> neighbours_;
  bool have_measurement_ = false;
  bool ever_measured_ = false;
  bool have_leader_ = false;
  bool ever_led_ = false;
  bool have_own_state_ = false;
  bool ever_own_state_ = false;
  bool have_neighbours_ = false;
  bool ever_neighbours_ = false;
};

}  // namespace projection_collision_avoidance
