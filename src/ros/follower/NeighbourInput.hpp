#pragma once

#include <cstdint>
#include <mutex>
#include <string>
#include <utility>
#include <vector>

#include <ros/ros.h>

#include "projection_collision_avoidance/NeighbourArray.h"
#include "projection_collision_avoidance/cycle/InputTimeline.hpp"
#include "projection_collision_avoidance/cycle/LatchedInputs.hpp"
#include "projection_collision_avoidance/rt/LatestValue.hpp"

#include "follower/FollowerOptions.hpp"

namespace projection_collision_avoidance {

/// The follower's `neighbours` input (formation.neighbours; doc/boundary.md): NeighbourArray
/// messages, each judged whole by its InputTimeline like `relative_measurement` (frame
/// ~measurement_frame, stamps within ~max_future_stamp and ~measurement_timeout, in order, one
/// publisher, ~clock_skew), then its content (neighbourSampleFromMsg(): at most
/// kMaxNeighbourEntries entries of the model's axes, finite, none named as the follower itself);
/// the nearest NeighbourSample::kCapacity agents of an accepted one go to the control cycle's
/// slot, the target's entry (named as the target) marked. A refused message leaves the slot as it
/// was: the cycle brakes once the latest accepted one is stale. Nothing a message carries ends
/// the node.
class NeighbourInput {
 public:
  /// @param slot the cycle's neighbour slot; outlives this object
  NeighbourInput(std::string node_name, const FollowerNodeOptions& options, int axes,
                 LatestValue<NeighbourSample>* slot);

  /// Subscribes `neighbours` on @p nh (its callback queue: the caller's) with @p link.
  void start(ros::NodeHandle& nh, const ros::TransportHints& link);

  /// The input's timeline (its counts, age and skew are readable from any thread).
  const InputTimeline& timeline() const { return timeline_; }
  /// The subscribed topic ("" before start()).
  std::string topic() const { return subscriber_.getTopic(); }
  /// The latest refusal's reason, "" once one was accepted after it (any thread).
  std::string rejection() const;

 private:
  void onNeighbours(const ros::MessageEvent<NeighbourArray const>& event);

  std::string name_;
  int axes_;
  std::string self_;    ///< the follower's own id
  std::string target_;  ///< its target's id
  LatestValue<NeighbourSample>* slot_;
  // The subscriber's thread only.
  InputTimeline timeline_;
  NeighbourSample sample_;
  std::vector<std::pair<double, std::size_t>> order_;  ///< reserved for kMaxNeighbourEntries
  std::string last_rejection_;
  mutable std::mutex rejection_mutex_;
  std::string rejection_;  ///< last_rejection_, for other threads (rejection_mutex_)
  ros::Subscriber subscriber_;
};

}  // namespace projection_collision_avoidance
