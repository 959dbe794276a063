#include "projection_collision_avoidance/ros/InputGuard.hpp"

#include <sstream>
#include <utility>

#include <ros/console.h>
#include <ros/this_node.h>

namespace projection_collision_avoidance {

InputGuard::InputGuard(std::string topic, std::string required_frame, double max_future_stamp)
    : topic_(std::move(topic)),
      required_frame_(std::move(required_frame)),
      max_future_stamp_(max_future_stamp) {}

bool InputGuard::checkHeader(const std_msgs::Header& header, const ros::Time& now) {
  if (!required_frame_.empty() && header.frame_id != required_frame_) {
    reject("frame_id '" + header.frame_id + "', expected '" + required_frame_ + "'");
    return false;
  }
  if ((header.stamp - now).toSec() > max_future_stamp_) {
    std::ostringstream why;
    why << "stamped " << (header.stamp - now).toSec() << " s in the future";
    reject(why.str());
    return false;
  }
  if (have_accepted_ && header.stamp < last_stamp_) {
    reject("stamped before the last accepted message");
    return false;
  }
  return true;
}

void InputGuard::reject(const std::string& reason) {
  ++rejected_;
  // The reason without its numbers decides whether this is a new kind of rejection.
  std::string kind;
  for (const char c : reason) {
    if ((c < '0' || c > '9') && c != '.' && c != '-') {
      kind += c;
    }
  }
  if (kind != last_kind_) {
    ROS_WARN_STREAM(ros::this_node::getName() << ": " << topic_ << " rejected: " << reason);
    last_kind_ = kind;
  } else {
    ROS_WARN_STREAM_THROTTLE(5.0, ros::this_node::getName() << ": " << topic_ << " rejected ("
                                                            << rejected_ << " so far): " << reason);
  }
  last_rejection_ = reason;
}

void InputGuard::accept(const ros::Time& stamp) {
  have_accepted_ = true;
  last_stamp_ = stamp;
  last_rejection_.clear();
  last_kind_.clear();
}

}  // namespace projection_collision_avoidance
