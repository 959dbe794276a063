#include "adapter/CommandAdapterOptions.hpp"

#include <sstream>

#include "projection_collision_avoidance/core/ParameterError.hpp"

namespace projection_collision_avoidance {
namespace {

constexpr double kDefaultOdometryAge = 0.25;  ///< s, ~odometry/max_age
/// m/s, ~velocity/max_speed and ~unicycle/max_speed: launch/vehicles.launch's limit; the
/// robots of test/enki set their own, lower ones.
constexpr double kDefaultMaxSpeed = 4.0;
/// rad/s, ~unicycle/max_yaw_rate: launch/vehicles.launch's limit.
constexpr double kDefaultMaxYawRate = 3.0;
constexpr double kLargestLimit = 1e4;  ///< m/s or rad/s

/// A limit of the outputs, > 0 and finite.
double limit(NodeOptionReader& reader, const std::string& key, double fallback) {
  return reader.number(key, fallback, 1e-6, kLargestLimit);
}

/// "body" or "header" (~odometry/twist_frame).
TwistFrame twistFrameOf(const std::string& value) {
  if (value == "body") {
    return TwistFrame::kBody;
  }
  if (value == "header") {
    return TwistFrame::kWorld;
  }
  throw ParameterError(
      "~odometry/twist_frame",
      "must be \"body\" (child_frame_id, REP 105) or \"header\", got \"" + value + "\"");
}

void readOutputs(NodeOptionReader& reader, CommandAdapterOptions* options) {
  std::istringstream words(reader.text("outputs", "twist"));
  std::string word;
  int count = 0;
  while (words >> word) {
    ++count;
    if (word == "accel_enu") {
      options->accel_enu = true;
    } else if (word == "twist") {
      options->twist = true;
    } else if (word == "twist_stamped") {
      options->twist_stamped = true;
    } else if (word == "unicycle") {
      options->unicycle = true;
    } else {
      throw ParameterError("~outputs", "\"" + word +
                                           "\" is not one of accel_enu, twist, twist_stamped, "
                                           "unicycle");
    }
  }
  if (count == 0) {
    throw ParameterError("~outputs",
                         "names no output: give one or more of accel_enu, twist, "
                         "twist_stamped, unicycle");
  }
  if (options->twist && options->unicycle) {
    throw ParameterError("~outputs", "has both twist and unicycle, which both publish cmd_vel");
  }
}

}  // namespace

CommandAdapterOptions readCommandAdapterOptions(NodeOptionReader& reader) {
  CommandAdapterOptions options;
  readOutputs(reader, &options);
  CommandConverterOptions& c = options.converter;
  c.axes = reader.integer("axes", c.axes, 1, 3);
  c.period = 1.0 / reader.number("control_rate", 1.0 / c.period, 1e-3, 1e5);
  options.command_timeout =
      reader.number("command_timeout", options.command_timeout, c.period, 3600.0);
  options.watchdog_rate = reader.number("watchdog_rate", options.watchdog_rate, 0.1, 1e4);
  options.max_future_stamp =
      reader.number("max_future_stamp", options.max_future_stamp, 0.0, 3600.0);
  // An odometry stays usable over one 100 ms burst of a simulated /clock and the delay of the
  // next (doc/boundary.md).
  c.max_odometry_age = reader.number("odometry/max_age", kDefaultOdometryAge, 0.0, 3600.0);
  c.odometry_twist_frame = twistFrameOf(reader.text("odometry/twist_frame", "body"));
  c.velocity.max_speed = limit(reader, "velocity/max_speed", kDefaultMaxSpeed);
  c.velocity.velocity_lag = reader.number("velocity/lag", 0.0, 0.0, 3600.0);
  c.velocity.max_measurement_age = c.max_odometry_age;
  // The response delay: < 0 estimated from the odometry against the commands sent.
  c.velocity.max_delay =
      reader.number("velocity/max_delay", c.velocity.max_delay, 0.0, 255.0 * c.period);
  c.velocity.delay = reader.number("velocity/delay", c.velocity.delay, -1.0, c.velocity.max_delay);
  c.velocity.averaging_time =
      reader.number("velocity/averaging_time", c.velocity.averaging_time, 1e-3, 3600.0);
  const std::string frame = reader.text("velocity/frame", "world");
  if (frame != "world" && frame != "base") {
    throw ParameterError("~velocity/frame", "must be \"world\" or \"base\", got \"" + frame + "\"");
  }
  c.velocity_in_base_frame = frame == "base";
  c.unicycle = options.unicycle;
  if (c.unicycle && c.axes != 2) {
    throw ParameterError(
        "~axes", "is " + std::to_string(c.axes) + " but the unicycle output is planar: set 2");
  }
  c.look_ahead = reader.number("unicycle/look_ahead", c.look_ahead, 1e-3, 100.0);
  c.unicycle_limits.max_speed = limit(reader, "unicycle/max_speed", kDefaultMaxSpeed);
  c.unicycle_limits.max_yaw_rate = limit(reader, "unicycle/max_yaw_rate", kDefaultMaxYawRate);
  c.stop_deceleration = reader.number("stop_deceleration", c.stop_deceleration, 1e-3, 1e3);
  options.base_frame = reader.frame("base_frame", "");
  options.world_frame = reader.frame("world_frame", "");
  options.pose_frame =
      poseFrameOf(reader.text("odometry/pose_frame", toString(options.pose_frame)));
  if (options.pose_frame == PoseFrame::kWorld && options.world_frame.empty()) {
    throw ParameterError("~world_frame",
                         "must name the world frame the odometry's pose is in with "
                         "~odometry/pose_frame \"world\"");
  }
  return options;
}

}  // namespace projection_collision_avoidance
