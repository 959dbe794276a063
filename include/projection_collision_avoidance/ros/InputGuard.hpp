#pragma once

#include <string>

#include <ros/time.h>
#include <std_msgs/Header.h>

namespace projection_collision_avoidance {

/// Admission of the messages of one input topic: checks what a message header can get wrong
/// (frame_id, a stamp in the future or before the last accepted one), counts every rejection
/// and logs it once per change of reason (then at most every 5 s). Content checks (sizes,
/// finiteness) are the caller's; it reports their failures through reject().
class InputGuard {
 public:
  /// @param topic name used in log messages
  /// @param required_frame frame_id a message must carry ("" accepts any)
  /// @param max_future_stamp s by which a stamp may lie ahead of now (clock offsets)
  InputGuard(std::string topic, std::string required_frame, double max_future_stamp);

  /// Checks @p header against the frame, now + max_future_stamp and the last accepted stamp.
  /// On failure counts and logs the rejection and returns false; the caller then drops the
  /// message. On success the caller checks the content and calls accept() or reject().
  bool checkHeader(const std_msgs::Header& header, const ros::Time& now);

  /// Counts and logs the rejection of a message for @p reason.
  void reject(const std::string& reason);

  /// Records an accepted message stamped @p stamp; the next rejection is logged again.
  void accept(const ros::Time& stamp);

  bool haveAccepted() const { return have_accepted_; }
  const ros::Time& lastStamp() const { return last_stamp_; }
  unsigned rejected() const { return rejected_; }
  /// Reason of the latest rejection, "" once a message was accepted after it.
  const std::string& lastRejection() const { return last_rejection_; }

 private:
  std::string topic_;
  std::string required_frame_;
  double max_future_stamp_;
  bool have_accepted_ = false;
  ros::Time last_stamp_;
  unsigned rejected_ = 0;
  std::string last_rejection_;
  std::string last_kind_;  ///< last_rejection_ without its numbers, for logging once per kind
};

}  // namespace projection_collision_avoidance
