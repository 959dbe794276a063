#pragma once

#include <cstdint>
#include <mutex>
#include <string>

#include <ros/ros.h>

#include "projection_collision_avoidance/LeaderBroadcast.h"
#include "projection_collision_avoidance/ros/InputAdmission.hpp"
#include "projection_collision_avoidance/sim/ReleaseQueue.hpp"
#include "projection_collision_avoidance/sim/SharedLink.hpp"

namespace projection_collision_avoidance {

/// The link relay's options, read once: the link and rate from ~scenario, the rest its own.
struct LinkRelayOptions {
  LinkSpec link;            ///< controller.leader_information.link of ~scenario
  double control_rate = 0;  ///< Hz, controller.control_rate of ~scenario
  int receiver = 1;         ///< ~receiver: index of the follower behind the relay (the losses' key)
  int max_in_flight = 10000;  ///< ~max_in_flight: messages held at most; the oldest go first
  /// ~max_in_flight_bytes: bytes held at most (serialised sizes); the oldest go first
  int max_in_flight_bytes = 16 * 1024 * 1024;
  /// ~max_future_stamp (s): a message stamped further ahead of ROS time is refused (two 100 ms
  /// bursts of a simulated /clock and 50 ms of transport, as the other nodes; doc/boundary.md)
  double max_future_stamp = 0.25;
};

/// A simulated network link between a target's `broadcast` and the follower that looks at it, for
/// experiments and tests on one machine: it impairs the shared information exactly as cf_sim's
/// link (doc/math.md (L1)-(L2); judgeLinkMessage()), on top of whatever the transport adds.
///
/// Subscribes `input` (LeaderBroadcast) and publishes each message unchanged, stamp included, on
/// `output`: lost with the scenario's dropout (by receiver and the sender's tick round(stamp f)),
/// otherwise when ROS time reaches stamp + D / f, D = delay_periods + ceil(latency f), checked
/// by a timer at f, each in the order of its release (a later message due earlier is not held
/// behind one due later; ties in arrival order). Without a link section (or an ideal one) every
/// message passes at once. A message stamped more than max_future_stamp ahead of ROS time is
/// refused; the messages held are bounded in count and bytes, the oldest dropped first; each is
/// counted. When ROS time goes back the messages in flight are dropped. Not part of a vehicle's
/// control path.
class LinkRelay {
 public:
  /// @throws ParameterError naming the key of a refused parameter
  LinkRelay(ros::NodeHandle nh, ros::NodeHandle private_nh);
  ~LinkRelay();
  LinkRelay(const LinkRelay&) = delete;
  LinkRelay& operator=(const LinkRelay&) = delete;

 private:
  void onMessage(const LeaderBroadcast::ConstPtr& msg);
  void onTick(const ros::TimerEvent& event);
  /// Publishes what is due at @p now (mutex_ held).
  void releaseDue(const ros::Time& now);

  std::string name_;
  LinkRelayOptions options_;
  int delay_periods_ = 0;  ///< D
  std::mutex mutex_;
  ReleaseQueue<LeaderBroadcast::ConstPtr> in_flight_;  ///< by release time (s)
  TimeJumpWatch clock_;
  std::uint64_t received_ = 0;
  std::uint64_t lost_ = 0;
  std::uint64_t passed_ = 0;
  std::uint64_t overflowed_ = 0;     ///< dropped (the oldest) or refused (too large) when full
  std::uint64_t future_stamps_ = 0;  ///< refused: stamped beyond max_future_stamp
  ros::Publisher publisher_;
  ros::Subscriber subscriber_;
  ros::Timer timer_;
};

}  // namespace projection_collision_avoidance
