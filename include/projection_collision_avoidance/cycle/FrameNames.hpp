#pragma once

/// @file
/// Frame names as tf2 knows them. Many ROS 1 drivers and simulator bridges write a leading slash
/// ("/robot_0/odom", the tf of ROS before tf2); tf2 drops one leading slash from every transform
/// it receives and refuses such a name in a lookup. Every frame name the package compares or
/// looks up (a message's header.frame_id and child_frame_id, a frame parameter) goes through
/// tfFrameName() first, so that "/robot_0/odom" and "robot_0/odom" name one frame. ROS-free.

#include <string>
#include <string_view>

namespace projection_collision_avoidance {

/// @p name without one leading '/', as tf2 strips it ("/a/b" -> "a/b", "//a" -> "/a", "" -> "").
inline std::string_view tfFrameName(std::string_view name) {
  return !name.empty() && name.front() == '/' ? name.substr(1) : name;
}

/// tfFrameName() as a string, for tf2's lookups and the frames the package publishes.
inline std::string tfFrame(std::string_view name) { return std::string(tfFrameName(name)); }

/// Whether @p a and @p b name the same frame for tf2 (equal up to a leading slash each).
inline bool sameFrame(std::string_view a, std::string_view b) {
  return tfFrameName(a) == tfFrameName(b);
}

/// Whether an odometry's @p header_frame (its pose's frame) and @p child_frame (its body's) name
/// one frame, and not the empty one: the pose of a frame in itself is the identity, so such a
/// message holds a pose in some other frame under its robot's name (a simulator's ground truth,
/// for instance, whose pose is in the world).
inline bool labelledWithItsOwnFrame(std::string_view header_frame, std::string_view child_frame) {
  return !tfFrameName(header_frame).empty() && sameFrame(header_frame, child_frame);
}

}  // namespace projection_collision_avoidance
