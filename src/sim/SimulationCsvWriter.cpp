#include "projection_collision_avoidance/sim/SimulationCsvWriter.hpp"

#include <ostream>
#include <string>

#include "projection_collision_avoidance/core/BallConstraint.hpp"

namespace projection_collision_avoidance {
namespace {

void writeHeaderColumns(std::ostream& out, const std::string& prefix, int count) {
  for (int i = 0; i < count; ++i) {
    out << ',' << prefix << i;
  }
}

void writeValues(std::ostream& out, const Eigen::VectorXd& values, int count) {
  for (int i = 0; i < count; ++i) {
    out << ',' << values(i);
  }
}

}  // namespace

SimulationCsvWriter::SimulationCsvWriter(std::ostream& out, const Scenario& scenario)
    : out_(out),
      states_(scenario.controller.model.stateDimension()),
      inputs_(scenario.controller.model.inputDimension()),
      positions_(scenario.controller.model.position_dimension),
      velocities_(scenario.controller.model.isDoubleIntegrator()),
      turning_(scenario.formation.slots == SlotFrame::kTurning),
      path_(scenario.formation.slots == SlotFrame::kPath),
      neighbours_(scenario.formation.neighbours.enabled),
      xi_max_(hardBound(scenario.controller.alpha, scenario.controller.separation.norm())),
      xi_soft_(softBound(xi_max_, scenario.controller.epsilon)),  // xi_max_ is set above
      perimeter_(
          safetyPerimeter(scenario.controller.alpha, scenario.controller.separation.norm())) {
  out_.precision(17);  // round-trip: a reader gets the very doubles
  out_ << 't';
  writeHeaderColumns(out_, "xi_", states_);
  writeHeaderColumns(out_, "xi_hat_", states_);
  out_ << ",norm_xi,norm_xi_hat,xi_max,xi_soft,f,projection_active";
  writeHeaderColumns(out_, "leader_p_", positions_);
  writeHeaderColumns(out_, "follower_p_", positions_);
  if (velocities_) {
    writeHeaderColumns(out_, "leader_v_", positions_);
    writeHeaderColumns(out_, "follower_v_", positions_);
  }
  out_ << ",separation,perimeter";
  writeHeaderColumns(out_, "u_", inputs_);
  writeHeaderColumns(out_, "u_baseline_", inputs_);
  writeHeaderColumns(out_, "u_tracker_", inputs_);
  writeHeaderColumns(out_, "leader_u_", inputs_);
  writeHeaderColumns(out_, "ud_", states_);
  if (turning_) {
    out_ << ",slot_heading,slot_yaw_rate,slot_yaw_acceleration";
    writeHeaderColumns(out_, "slot_p_", positions_);
    writeHeaderColumns(out_, "u_slot_", inputs_);
  }
  if (path_) {
    writeHeaderColumns(out_, "slot_p_", positions_);
    writeHeaderColumns(out_, "u_slot_", inputs_);
    writeHeaderColumns(out_, "ref_p_", positions_);
    writeHeaderColumns(out_, "goal_p_", positions_);
    out_ << ",progress,goal_arc,chord,braking";
  }
  if (neighbours_) {
    out_ << ",command_projected,constraints_given,constraints_active,constraints_dropped";
  }
  out_ << '\n';
}

void SimulationCsvWriter::write(const SimulationSample& s) {
  out_ << s.time;
  writeValues(out_, s.relative_error, states_);
  writeValues(out_, s.controller.estimate, states_);
  out_ << ',' << s.relative_error.norm() << ',' << s.controller.estimate.norm() << ',' << xi_max_
       << ',' << xi_soft_ << ',' << s.controller.constraint_value << ','
       << (s.controller.projection_active ? 1 : 0);
  writeValues(out_, s.leader_state, positions_);
  writeValues(out_, s.follower_state, positions_);
  if (velocities_) {
    writeValues(out_, s.leader_state.tail(positions_), positions_);
    writeValues(out_, s.follower_state.tail(positions_), positions_);
  }
  out_ << ',' << s.distance << ',' << perimeter_;
  writeValues(out_, s.controller.command, inputs_);
  writeValues(out_, s.controller.baseline_command, inputs_);
  writeValues(out_, s.controller.tracker_command, inputs_);
  writeValues(out_, s.leader_input, inputs_);
  writeValues(out_, s.disturbance, states_);
  if (turning_) {
    out_ << ',' << s.slot_heading.angle << ',' << s.slot_heading.rate << ','
         << s.slot_heading.acceleration;
    writeValues(out_, s.slot, positions_);
    writeValues(out_, s.controller.slot_command, inputs_);
  }
  if (path_) {
    writeValues(out_, s.slot, positions_);
    writeValues(out_, s.controller.slot_command, inputs_);
    writeValues(out_, s.convoy.position, positions_);
    writeValues(out_, s.convoy.goal, positions_);
    out_ << ',' << s.convoy.progress << ',' << s.convoy.goal_arc << ',' << s.convoy.chord << ','
         << (s.convoy.braking ? 1 : 0);
  }
  if (neighbours_) {
    out_ << ',' << (s.controller.command_projected ? 1 : 0) << ',' << s.controller.constraints_given
         << ',' << s.controller.constraints_active << ',' << s.controller.constraints_dropped;
  }
  out_ << '\n';
}

}  // namespace projection_collision_avoidance
