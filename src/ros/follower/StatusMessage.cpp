#include "follower/StatusMessage.hpp"

#include "projection_collision_avoidance/ros/InputAdmission.hpp"
#include "projection_collision_avoidance/ros/MessageConversions.hpp"

namespace projection_collision_avoidance {

FollowerStatus toStatusMsg(const FollowerCycleOutput& out, const FollowerInputStats& inputs,
                           const FormationMember& member, const std::string& frame) {
  const DynamicFollowerStatus& s = out.status;
  FollowerStatus msg;
  msg.header.stamp = rosTimeOf(out.stamp_ns);
  msg.header.frame_id = frame;
  msg.formation_index = static_cast<uint32_t>(member.index);
  msg.target = member.target_name;
  msg.mode = static_cast<uint8_t>(out.mode);
  msg.mode_name = toString(out.mode);
  msg.fallback = s.fallback;
  msg.measurement_fresh =
      out.mode == FollowerMode::kTracking || out.mode == FollowerMode::kLeaderLost;
  msg.measurement_age = out.measurement_age;
  msg.rejected_measurements = static_cast<uint32_t>(inputs.rejected_measurements);
  msg.leader_fresh = out.leader_fresh;
  msg.leader_age = out.leader_age;  // +inf when none on this timeline
  msg.rejected_leader_broadcasts = static_cast<uint32_t>(inputs.rejected_leader_broadcasts);
  msg.measurement_skew = inputs.measurement_skew;
  msg.clock_offset = inputs.clock_offset;
  msg.xi = toStdVector(out.xi);
  msg.xi_hat = toStdVector(s.estimate);
  msg.xi_norm = out.xi.norm();
  msg.xi_hat_norm = s.estimate_norm;
  msg.xi_max = out.xi_max;
  msg.xi_soft = out.xi_soft;
  msg.margin = out.xi_max - msg.xi_norm;
  msg.constraint = s.constraint_value;
  msg.projection_active = s.projection_active;
  msg.command_saturated = s.command_saturated;
  msg.acceleration_limit = out.acceleration_limit;
  msg.command_rate_limited = s.command_rate_limited;
  msg.jerk_limit = out.jerk_limit;
  msg.tracker_enabled = out.tracker_enabled;
  msg.command = toStdVector(s.command);
  msg.baseline_command = toStdVector(s.baseline_command);
  msg.tracker_command = toStdVector(s.tracker_command);
  msg.feedforward_command = toStdVector(s.feedforward_command);
  msg.headway_command = toStdVector(s.headway_command);
  msg.own_state_fresh = out.own_state_fresh;
  msg.fallback_command = toStdVector(s.fallback_command);
  msg.slot = toStdVector(out.slot);
  msg.slot_heading = out.slot_heading.angle;
  msg.slot_yaw_rate = out.slot_heading.rate;
  msg.heading_known = out.heading_known;
  msg.slot_command = toStdVector(s.slot_command);
  msg.distance = out.distance;
  msg.perimeter = out.perimeter;
  msg.ticks = out.steps;
  msg.missed_periods = out.missed_periods;
  msg.late_periods = out.late_periods;
  msg.held_measurements = out.held_measurements;
  msg.tick_delay = out.tick_delay;
  msg.time_jumps = out.time_jumps;
  const NeighbourReport& n = out.neighbours;
  msg.neighbours_configured = n.configured;
  if (n.configured) {
    msg.neighbours_fresh = n.fresh;
    msg.neighbours_age = n.age;
    msg.rejected_neighbours = static_cast<uint32_t>(inputs.rejected_neighbours);
    msg.neighbours_sent = static_cast<uint32_t>(n.sent);
    msg.neighbours_sensed = static_cast<uint32_t>(n.sensed);
    msg.neighbour_constraints = static_cast<uint32_t>(n.kept);
    msg.neighbour_constraints_active = static_cast<uint32_t>(n.active);
    msg.neighbour_constraints_dropped = static_cast<uint32_t>(n.dropped);
    msg.neighbour_projected = n.projected;
    msg.nearest_neighbour = n.nearest;
    msg.neighbour_barrier = n.smallest_barrier;
    msg.binding_neighbour = n.binding_id.data();
  }
  const BarrierReport& b = out.barriers;
  msg.barrier_filter = b.configured;
  if (b.configured) {
    msg.barriers = static_cast<uint32_t>(b.barriers);
    msg.barriers_active = static_cast<uint32_t>(b.active);
    msg.barriers_dropped = static_cast<uint32_t>(b.dropped);
    msg.barrier_projected = b.projected;
    msg.barrier_infeasible = b.infeasible;
    msg.target_barrier = b.target_barrier;
    msg.binding_barrier = b.binding_id.data();
  }
  return msg;
}

}  // namespace projection_collision_avoidance
