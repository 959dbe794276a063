#include "projection_collision_avoidance/ros/LinkRelay.hpp"

#include <exception>

#include "projection_collision_avoidance/ros/RosParameters.hpp"
#include "projection_collision_avoidance/ros/ScenarioParameters.hpp"

namespace projection_collision_avoidance {

LinkRelay::LinkRelay(ros::NodeHandle nh, ros::NodeHandle private_nh)
    : name_(private_nh.getNamespace()) {
  const Scenario scenario = loadDoubleIntegratorScenario(private_nh);
  NodeOptionReader reader(private_nh);
  options_.link = scenario.link;
  options_.control_rate = scenario.controller.control_rate;
  options_.receiver =
      reader.integer("receiver", options_.receiver, 1, FormationSpec::kMaxFollowers);
  options_.max_in_flight = reader.integer("max_in_flight", options_.max_in_flight, 1, 1000000);
  reader.echo(name_);
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
                        << passed_ << ", dropped when full " << overflowed_);
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
    const LinkVerdict verdict = judgeLinkMessage(options_.link, options_.control_rate,
                                                 options_.receiver, msg->header.stamp.toSec());
    if (verdict.lost) {
      ++lost_;
      return;
    }
    if (static_cast<int>(in_flight_.size()) >= options_.max_in_flight) {
      in_flight_.pop_front();
      ++overflowed_;
      ROS_WARN_STREAM_THROTTLE(10.0, name_ << ": more than " << options_.max_in_flight
                                           << " messages in flight: dropping the oldest");
    }
    in_flight_.emplace_back(verdict.release, msg);
    releaseDue(ros::Time::now());
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
  while (!in_flight_.empty() && in_flight_.front().first <= horizon) {
    publisher_.publish(in_flight_.front().second);
    in_flight_.pop_front();
    ++passed_;
  }
}

}  // namespace projection_collision_avoidance
