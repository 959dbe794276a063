#pragma once

#include <cstdint>
#include <functional>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <geometry_msgs/TransformStamped.h>
#include <geometry_msgs/Twist.h>
#include <geometry_msgs/TwistStamped.h>
#include <ros/ros.h>

#include "projection_collision_avoidance/cycle/InputTimeline.hpp"
#include "projection_collision_avoidance/cycle/StampCorrection.hpp"
#include "projection_collision_avoidance/sim/VehicleModels.hpp"

#include "plant/PlantOptions.hpp"

namespace projection_collision_avoidance {

/// A plant agent of a vehicle kind (~vehicles/<agent>/kind `velocity` or `unicycle`): its model
/// (VelocityLagVehicle, UnicycleVehicle), its velocity commands and its odometry as a real base
/// publishes it.
///
/// Subscribes `<agent>/cmd_vel` (geometry_msgs/Twist) and `<agent>/cmd_vel_stamped`
/// (geometry_msgs/TwistStamped), each on an InputTimeline of its own: a Twist, without a header,
/// is stamped at its receipt; a TwistStamped's header is judged as the plant's commands are (a
/// zero stamp, one ahead of or behind the plant's time by more than the command timeout after
/// ~clock_skew's offset, one not after the last; any frame_id). A message with any non-finite
/// field is refused; refusals are counted and logged per topic. The latest accepted command of
/// either topic is held and, once older than the command timeout by its receipt (plant) time,
/// replaced by zero: the vehicle stops. `velocity`: the linear part, in the body frame (turned into
/// the world by the fixed heading) or the world frame (twist_frame), on the model's axes (others
/// ignored), angular ignored; `unicycle`: linear.x and angular.z, the rest ignored.
///
/// Publishes `<agent>/odom` (REP 105: pose in the world frame with the yaw, twist in the body
/// frame, the agent's frame as child; with an odom_frame, the pose in that frame, which starts at
/// the vehicle's initial pose as a real base's odometry does, and tf odom_frame -> the agent's
/// frame) and `<agent>/applied_command` (geometry_msgs/TwistStamped:
/// the command integrated over each tick, after the timeout and the limits; `velocity`: linear in
/// the world frame, frame_id the world frame; `unicycle`: linear.x = v, angular.z = ω, frame_id
/// the agent's).
class PlantVehicle {
 public:
  /// Where the vehicle lives in the plant.
  struct Setup {
    std::string node_name;   ///< the plant's name, for log lines
    std::string agent_name;  ///< topic prefix ("leader", "follower_2")
    std::string frame;       ///< the agent's (body) frame
    std::string world_frame;
    int axes = 1;                  ///< k of the scenario's model
    double command_timeout = 0.5;  ///< s of plant time since receipt
    /// How cmd_vel_stamped's stamps are put on the plant's clock (~clock_skew).
    StampCorrectionOptions clock_skew;
  };

  /// @param initial_state [p; v] (2k entries) of the scenario; a unicycle takes the velocity's
  ///        part along its heading (the rest dropped, with a warning) and, in 3-D, keeps z
  /// @throws ParameterError naming options.key + "/velocity_lag" and so on
  PlantVehicle(const VehicleOptions& options, Setup setup, const Eigen::VectorXd& initial_state);

  /// Advertises and subscribes the topics above on @p nh; the callbacks lock @p mutex and take
  /// the receipt time from @p now.
  void connect(ros::NodeHandle& nh, std::mutex* mutex, std::function<ros::Time()> now);

  /// [p; v] (2k entries, m and m/s, world): the odometry's origin and its world velocity.
  Eigen::VectorXd state() const;
  /// With an odom_frame: the static transform world -> odom_frame (the initial pose), stamped
  /// @p stamp; false without one.
  bool odomFrameTransform(const ros::Time& stamp, geometry_msgs::TransformStamped* transform) const;
  /// Publishes the odometry stamped @p stamp and appends the tf world (or odom_frame) -> the
  /// agent's frame.
  void publishSample(const ros::Time& stamp,
                     std::vector<geometry_msgs::TransformStamped>* transforms) const;
  /// Integrates @p h (s) with the command held at plant time @p stamp, and publishes it.
  void advance(double h, const ros::Time& stamp);
  /// Plant time went back: the held command and both inputs' timelines are forgotten (a stop
  /// until the next command).
  void restartTimeline();
  /// Whether a follower drives it: its odometry has a subscriber and cmd_vel or cmd_vel_stamped
  /// a publisher.
  bool driven() const {
    return odom_publisher_.getNumSubscribers() > 0 &&
           (twist_subscriber_.getNumPublishers() > 0 || stamped_subscriber_.getNumPublishers() > 0);
  }
  /// The body frame's yaw in the world (rad).
  double yaw() const;
  /// Lockstep: whether the vehicle answered the sample stamped @p sample: a command received at
  /// plant time @p sample or later, no command yet, or nobody publishing cmd_vel or
  /// cmd_vel_stamped.
  /// Lockstep: whether it has been commanded, or nobody publishes cmd_vel or cmd_vel_stamped.
  bool commanded() const {
    return have_command_ || (twist_subscriber_.getNumPublishers() == 0 &&
                             stamped_subscriber_.getNumPublishers() == 0);
  }
  bool answered(const ros::Time& sample) const {
    return !have_command_ || received_ >= sample ||
           (twist_subscriber_.getNumPublishers() == 0 &&
            stamped_subscriber_.getNumPublishers() == 0);
  }

 private:
  /// The command of a Twist's content; false, with the reason, when it is refused.
  bool commandOf(const geometry_msgs::Twist& twist, Eigen::Vector3d* command,
                 std::string* why) const;
  void onTwist(const geometry_msgs::Twist& twist, std::string_view publisher);
  void onTwistStamped(const geometry_msgs::TwistStamped& message, std::string_view publisher);
  /// Holds @p twist received at @p now, admitted so far by @p timeline: its content judged, then
  /// accepted or refused there.
  void hold(InputTimeline* timeline, const geometry_msgs::Twist& twist, const ros::Time& now);

  VehicleKind kind_;
  bool twist_in_body_;
  Setup setup_;
  std::optional<VelocityLagVehicle> velocity_;
  std::optional<UnicycleVehicle> unicycle_;
  double z_ = 0.0;                                         ///< the unicycle's height in 3-D (m)
  std::string odom_frame_;                                 ///< "": the world frame
  Eigen::Vector3d odom_origin_ = Eigen::Vector3d::Zero();  ///< the initial position (world)
  double odom_yaw_ = 0.0;                                  ///< the initial yaw (rad)

  std::mutex* mutex_ = nullptr;
  std::function<ros::Time()> now_;
  InputTimeline twist_timeline_;                       ///< cmd_vel: stamped at receipt
  InputTimeline stamped_timeline_;                     ///< cmd_vel_stamped: its header judged
  Eigen::Vector3d command_ = Eigen::Vector3d::Zero();  ///< held: world velocity or (v, ω, 0)
  bool have_command_ = false;
  ros::Time received_;      ///< plant time of the held command's receipt
  bool timed_out_ = false;  ///< the last tick stopped for lack of a fresh command
  ros::Subscriber twist_subscriber_;
  ros::Subscriber stamped_subscriber_;
  ros::Publisher odom_publisher_;
  ros::Publisher applied_publisher_;
};

}  // namespace projection_collision_avoidance
