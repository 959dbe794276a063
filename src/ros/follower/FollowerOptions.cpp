#include "follower/FollowerOptions.hpp"

#include <string>

#include "projection_collision_avoidance/core/ParameterError.hpp"

namespace projection_collision_avoidance {
namespace {

ControlTrigger triggerOf(const std::string& value) {
  if (value == "timer") {
    return ControlTrigger::kTimer;
  }
  if (value == "measurement") {
    return ControlTrigger::kMeasurement;
  }
  throw ParameterError("~trigger", "must be \"timer\" or \"measurement\", got \"" + value + "\"");
}

/// ~control_loop; "thread" is refused on simulated time (@p sim_time).
ControlLoop controlLoopOf(const std::string& value, bool sim_time) {
  if (value == "timer") {
    return ControlLoop::kTimer;
  }
  if (value == "thread") {
    if (sim_time) {
      throw ParameterError("~control_loop",
                           "\"thread\" sleeps on the monotonic clock and cannot follow simulated "
                           "time (/use_sim_time is true): use \"timer\"");
    }
    return ControlLoop::kThread;
  }
  throw ParameterError("~control_loop", "must be \"timer\" or \"thread\", got \"" + value + "\"");
}

MeasurementInput inputOf(const std::string& value) {
  for (const MeasurementInput input :
       {MeasurementInput::kRelativeMeasurement, MeasurementInput::kOdometry,
        MeasurementInput::kPosition, MeasurementInput::kTf}) {
    if (value == toString(input)) {
      return input;
    }
  }
  throw ParameterError(
      "~input", "must be \"relative_measurement\", \"odometry\", \"position\" or \"tf\", got \"" +
                    value + "\"");
}

/// ~odometry/...: all of them for ~input odometry (@p input), else (the time headway's own
/// odometry) the conventions and the quaternion tolerance. @p world_frame is ~measurement_frame.
OdometryInputOptions readOdometryOptions(NodeOptionReader& reader, bool input,
                                         const std::string& world_frame) {
  OdometryInputOptions o;
  o.quaternion_tolerance =
      reader.number("odometry/quaternion_tolerance", o.quaternion_tolerance, 0.0, 1.0);
  const std::string frame = reader.text("odometry/twist_frame", "body");
  if (frame != "body" && frame != "header") {
    throw ParameterError("~odometry/twist_frame",
                         "must be \"body\" (child_frame_id, REP 105) or \"header\" "
                         "(header.frame_id), got \"" +
                             frame + "\"");
  }
  o.twist_in_body_frame = frame == "body";
  o.pose_frame = poseFrameOf(reader.text("odometry/pose_frame", toString(o.pose_frame)));
  if (!input) {
    return o;
  }
  if (o.pose_frame == PoseFrame::kWorld && world_frame.empty()) {
    throw ParameterError("~measurement_frame",
                         "must name the world frame the odometries' poses are in with "
                         "~odometry/pose_frame \"world\"");
  }
  o.max_skew = reader.number("odometry/max_skew", o.max_skew, 0.0, 3600.0);
  o.look_ahead = reader.number("odometry/look_ahead", o.look_ahead, 0.0, 1000.0);
  o.target_look_ahead =
      reader.number("odometry/target_look_ahead", o.target_look_ahead, 0.0, 1000.0);
  o.tf_timeout = reader.number("odometry/tf_timeout", o.tf_timeout, 0.0, 10.0);
  return o;
}

std::string requiredFrame(NodeOptionReader& reader, const std::string& key) {
  const std::string frame = reader.frame(key, "");
  if (frame.empty()) {
    throw ParameterError("~" + key, "must name a tf frame with ~input tf");
  }
  return frame;
}

/// ~position/... (and, for the tf input, ~tf/...); @p world_frame is ~measurement_frame.
PositionInputOptions readPositionOptions(NodeOptionReader& reader, MeasurementInput input,
                                         const std::string& world_frame, double control_rate,
                                         double measurement_timeout) {
  PositionInputOptions o;
  o.velocity_bandwidth =
      reader.number("position/velocity_bandwidth", o.velocity_bandwidth, 1e-3, 1e4);
  o.max_gap = reader.number("position/max_gap", measurement_timeout, 1e-6, 3600.0);
  o.min_interval = reader.number("position/min_interval", o.min_interval, 1e-6, 3600.0);
  if (!(o.min_interval < o.max_gap)) {
    throw ParameterError("~position/min_interval", "must be below ~position/max_gap (" +
                                                       std::to_string(o.max_gap) +
                                                       " s), or no position is ever used");
  }
  o.max_speed = reader.number("position/max_speed", o.max_speed, 1e-3, 1e6);
  o.tf_timeout = reader.number("position/tf_timeout", o.tf_timeout, 0.0, 10.0);
  if (input != MeasurementInput::kTf) {
    return o;
  }
  if (world_frame.empty()) {
    throw ParameterError("~measurement_frame",
                         "must name the world frame in which ~input tf looks the agents up");
  }
  o.self_frame = requiredFrame(reader, "tf/self_frame");
  o.target_frame = requiredFrame(reader, "tf/target_frame");
  o.rate = reader.number("tf/rate", control_rate, 1e-3, control_rate);
  o.max_skew = reader.number("tf/max_skew", o.max_skew, 0.0, 3600.0);
  o.look_ahead = reader.number("tf/look_ahead", o.look_ahead, 0.0, 1000.0);
  o.target_look_ahead = reader.number("tf/target_look_ahead", o.target_look_ahead, 0.0, 1000.0);
  return o;
}

}  // namespace

/// Member ~formation_index of the configured formation.
FormationMember memberOf(NodeOptionReader& reader, const FollowerConfiguration& configuration) {
  const int index = reader.integer("formation_index", 1, 1, FormationSpec::kMaxFollowers);
  return configuration.member(index, "~formation_index");
}

FollowerNodeOptions readFollowerOptions(NodeOptionReader& reader, const ControllerParameters& p,
                                        const FormationMember& member, bool sim_time) {
  FollowerNodeOptions options;
  options.formation_index = member.index;
  const double period = 1.0 / p.control_rate;
  options.measurement_timeout =
      reader.number("measurement_timeout", options.measurement_timeout, period, 3600.0);
  options.leader_timeout = reader.number("leader_timeout", options.leader_timeout, period, 3600.0);
  options.max_future_stamp =
      reader.number("max_future_stamp", options.max_future_stamp, 0.0, 3600.0);
  options.use_leader_broadcast = reader.boolean("use_leader_broadcast", false);
  options.measurement_frame = reader.frame("measurement_frame", "");
  options.leader_broadcast_frame = reader.frame("leader_broadcast_frame", "");
  options.odom_frame = reader.frame("odom_frame", "");
  options.follower_frame = reader.frame("follower_frame", member.name);
  if (options.follower_frame.empty()) {
    throw ParameterError("~follower_frame", "must not be empty");
  }
  options.marker_rate = reader.number("marker_rate", options.marker_rate, 0.0, p.control_rate);
  options.status_rate = reader.number("status_rate", p.control_rate, 0.0, p.control_rate);
  options.trigger = triggerOf(reader.text("trigger", toString(options.trigger)));
  options.control_loop =
      controlLoopOf(reader.text("control_loop", toString(options.control_loop)), sim_time);
  options.control_priority =
      reader.integer("control_priority", options.control_priority, 0, kMaxControlPriority);
  if (options.control_priority > 0 && options.control_loop != ControlLoop::kThread) {
    throw ParameterError("~control_priority",
                         "is " + std::to_string(options.control_priority) +
                             " but only the \"thread\" control loop has a priority: set "
                             "~control_loop to \"thread\", or this to 0");
  }
  options.lock_memory = reader.boolean("lock_memory", options.lock_memory);
  const std::string transport = reader.text("transport", toString(options.transport));
  if (transport != "tcp" && transport != "udp") {
    throw ParameterError("~transport", "must be \"tcp\" or \"udp\", got \"" + transport + "\"");
  }
  options.transport = transport == "udp" ? Transport::kUdp : Transport::kTcp;
  options.clock_skew = readClockSkewOptions(reader);
  options.input = inputOf(reader.text("input", toString(options.input)));
  if (options.input == MeasurementInput::kOdometry || p.time_headway > 0.0) {
    options.odometry = readOdometryOptions(reader, options.input == MeasurementInput::kOdometry,
                                           options.measurement_frame);
  }
  if (options.input == MeasurementInput::kPosition || options.input == MeasurementInput::kTf) {
    options.position = readPositionOptions(reader, options.input, options.measurement_frame,
                                           p.control_rate, options.measurement_timeout);
  }
  return options;
}

const char* toString(ControlTrigger trigger) {
  return trigger == ControlTrigger::kMeasurement ? "measurement" : "timer";
}

const char* toString(MeasurementInput input) {
  switch (input) {
    case MeasurementInput::kOdometry:
      return "odometry";
    case MeasurementInput::kPosition:
      return "position";
    case MeasurementInput::kTf:
      return "tf";
    case MeasurementInput::kRelativeMeasurement:
    default:
      return "relative_measurement";
  }
}

const char* toString(Transport transport) { return transport == Transport::kUdp ? "udp" : "tcp"; }

const char* toString(ControlLoop loop) { return loop == ControlLoop::kThread ? "thread" : "timer"; }

}  // namespace projection_collision_avoidance
