#include "projection_collision_avoidance/ros/LinkRelay.hpp"

#include <cstddef>
#include <exception>
#include <limits>

#include "projection_collision_avoidance/ros/RosParameters.hpp"
#include "projection_collision_avoidance/ros/ScenarioParameters.hpp"

namespace projection_collision_avoidance {

namespace {

/// The options, each validated (the message names the key).
LinkRelayOptions readOptions(const ros::NodeHandle& private_nh) {
  const Scenario scenario = loadDoubleIntegratorScenario(private_nh);
  NodeOptionReader reader(private_nh);
  LinkRelayOptions options;
  options.link = scenario.link;
  options.control_rate = scenario.controller.control_rate;
  options.receiver = reader.integer("receiver", options.receiver, 1, FormationSpec::kMaxFollowers);
  options.max_in_flight = reader.integer("max_in_flight", options.max_in_flight, 1, 1000000);
  options.max_in_flight_bytes = reader.integer("max_in_flight_bytes", options.max_in_flight_bytes,
                                               1024, std::numeric_limits<int>::max());
  options.max_future_stamp =
      reader.number("max_future_stamp", options.max_future_stamp, 0.0, 3600.0);
  reader.echo(private_nh.getNamespace());
  return options;
}

}  // namespace

LinkRelay::LinkRelay(ros::NodeHandle nh, ros::NodeHandle private_nh)
    : name_(private_nh.getNamespace()),
      options_(readOptions(private_nh)),
      in_flight_(static_cast<std::size_t>(options_.max_in_flight),
                 static_cast<std::size_t>(options_.max_in_flight_bytes)) {
  delay_periods_ = options_.link.totalDelayPeriods(options_.control_rate);
  publisher_ = nh.advertise<LeaderBroadcast>("output", 10);
  subscriber_ =
      nh.subscribe("input", 100, &LinkRelay::onMessage, this, ros::TransportHints().tcpNoDelay());
  if (options_.link.active()) {
    timer_ = nh.createTimer(ros::Duration(1.0 / options_.control_rate), &LinkRelay::onTick, this);
  }
  ROS_INFO_STREAM(name_ << ": " << subscriber_.getTopic() << " -> " << publisher_.getTopic()
                        << (options_.link.active()
                                ? ": delay " + std::to_string(delay_periods_) + " periods of " +
                                      std::to_string(1.0 / options_.control_rate) + " s, dropout " +
                                      std::to_string(options_.link.dropout) + ", seed " +
                                      std::to_string(options_.link.seed) + ", receiver " +
                                      std::to_string(options_.receiver)
                                : std::string(": no link in the scenario, passing every message")));
}

LinkRelay::~LinkRelay() {
  timer_.stop();
  ROS_INFO_STREAM(name_ << ": received " << received_ << ", lost " << lost_ << ", passed "
                        << passed_ << ", dropped when full " << overflowed_
                        << ", refused as stamped ahead " << future_stamps_);
}

void LinkRelay::onMessage(const LeaderBroadcast::ConstPtr& msg) {
  const std::lock_guard<std::mutex> lock(mutex_);
  try {
    ++received_;
    if (!options_.link.active()) {
      publisher_.publish(msg);
      ++passed_;
      return;
    }
    const ros::Time now = ros::Time::now();
    if (msg->header.stamp.toSec() > now.toSec() + options_.max_future_stamp) {
      // Held until then, it would hold the link's memory and say nothing sooner.
      ++future_stamps_;
      ROS_WARN_STREAM_THROTTLE(10.0, name_ << ": a message stamped "
                                           << msg->header.stamp.toSec() - now.toSec()
                                           << " s ahead (> ~max_future_stamp) refused ("
                                           << future_stamps_ << " in all)");
      return;
    }
    const LinkVerdict verdict = judgeLinkMessage(options_.link, options_.control_rate,
                                                 options_.receiver, msg->header.stamp.toSec());
    if (verdict.lost) {
      ++lost_;
      return;
    }
    const auto pushed =
        in_flight_.push(verdict.release, ros::serialization::serializationLength(*msg), msg);
    const std::size_t dropped = pushed.dropped + (pushed.accepted ? 0 : 1);
    if (dropped > 0) {
      overflowed_ += dropped;
      ROS_WARN_STREAM_THROTTLE(10.0, name_ << ": more than " << options_.max_in_flight
                                           << " messages or " << options_.max_in_flight_bytes
                                           << " bytes in flight: dropping the oldest ("
                                           << overflowed_ << " in all)");
    }
    releaseDue(now);
  } catch (const std::exception& error) {
    ROS_ERROR_STREAM_THROTTLE(5.0, name_ << ": message not relayed: " << error.what());
  }
}

void LinkRelay::onTick(const ros::TimerEvent& /*event*/) {
  const std::lock_guard<std::mutex> lock(mutex_);
  releaseDue(ros::Time::now());
}

void LinkRelay::releaseDue(const ros::Time& now) {
  if (wentBack(clock_, now)) {
    ROS_WARN_STREAM(name_ << ": ROS time went back: " << in_flight_.size()
                          << " message(s) in flight dropped");
    in_flight_.clear();
    return;
  }
  // A release on a tick counts as on it (1e-9 periods), as in (L1).
  const double horizon = now.toSec() + 1e-9 / options_.control_rate;
  while (!in_flight_.empty() && in_flight_.nextRelease() <= horizon) {
    publisher_.publish(in_flight_.pop());
    ++passed_;
  }
}

}  // namespace projection_collision_avoidance
