#pragma once

#include <limits>
#include <string>

#include <Eigen/Core>
#include <tf2_ros/buffer.h>

namespace projection_collision_avoidance {

/// The follower's command brought into the command adapter's world frame. The follower names
/// the frame its acceleration is expressed in (its measurements' world frame; its own body's
/// name when it knows none). A command in another frame than the adapter's world frame and its
/// base frame is turned by the rotation world ← command frame that tf2 holds (the latest
/// transform), looked up again at most every kRefreshPeriod s; until the first lookup succeeds it
/// is tried every kRetryPeriod s. A command in the base frame (a follower that knows no world
/// names its body) or an empty frame is taken as it is: the body's name cannot be told apart
/// from a world frame's, and its rotation would be the body's heading, not a world's.
///
/// When the two frames have not been joined kJoinGrace s after the first command of the pair,
/// the command is taken as it is and the node warns once (warning() gives the text for the
/// diagnostics until a lookup succeeds). A lookup that fails after one succeeded keeps the
/// rotation found. Lookups allocate; between them toWorld() allocates nothing.
class CommandFrame {
 public:
  static constexpr double kRefreshPeriod = 1.0;  ///< s between lookups once joined
  static constexpr double kRetryPeriod = 0.1;    ///< s between lookups before the first success
  static constexpr double kJoinGrace = 1.0;      ///< s tf2 has to join the frames before a warning

  /// @param node_name for the log lines
  /// @param buffer the node's tf2 buffer; outlives this object
  /// @param world_from_odometry the world frame is the odometry's header frame (no ~world_frame)
  CommandFrame(std::string node_name, const tf2_ros::Buffer* buffer, bool world_from_odometry);

  /// Turns @p acceleration (m/s², its first two or three entries the x, y[, z] axes) from
  /// @p command_frame into @p world_frame, at steady time @p now (s).
  /// @param world_frame the adapter's world frame ("" while none is known: taken as it is)
  /// @param base_frame the adapter's base frame (a command in it is taken as it is)
  void toWorld(const std::string& command_frame, const std::string& world_frame,
               const std::string& base_frame, double now, Eigen::VectorXd* acceleration);

  /// The warning while the frames are not joined past the grace time; "" otherwise.
  const std::string& warning() const { return warning_; }
  /// Whether the latest command was turned by a rotation from tf2.
  bool turned() const { return turned_; }

 private:
  /// Looks the rotation up (at steady time @p now); warns when the grace time is over.
  void lookUp(double now);

  std::string name_;
  const tf2_ros::Buffer* buffer_;
  bool world_from_odometry_;
  std::string frame_;  ///< the command frame of the pair looked up (tfFrameName())
  std::string world_;  ///< its world frame (tfFrameName())
  Eigen::Matrix3d rotation_ = Eigen::Matrix3d::Identity();  ///< world ← frame_
  bool joined_ = false;                                     ///< rotation_ was found for the pair
  bool warned_ = false;                                     ///< the warning was logged
  bool turned_ = false;
  double since_ = 0.0;  ///< steady s of the pair's first command
  double next_lookup_ = -std::numeric_limits<double>::infinity();
  std::string warning_;
};

}  // namespace projection_collision_avoidance
