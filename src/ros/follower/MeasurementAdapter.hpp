#pragma once

#include <cstdint>
#include <functional>
#include <limits>
#include <memory>
#include <string>

#include <Eigen/Core>
#include <ros/ros.h>

#include "projection_collision_avoidance/RelativeMeasurement.h"
#include "projection_collision_avoidance/cycle/InputTimeline.hpp"

#include "follower/FollowerOptions.hpp"

namespace projection_collision_avoidance {

/// An input that makes the follower's relative measurements out of what a vehicle stack
/// publishes (~input other than relative_measurement; doc/vehicles.md): each measurement it
/// makes goes to its sink, which judges it like a received RelativeMeasurement
/// (FollowerInputs::admitMeasurement()).
class MeasurementAdapter {
 public:
  using Sink = std::function<void(const RelativeMeasurement&)>;

  virtual ~MeasurementAdapter() = default;
  /// Subscribes (or starts its timer), once the sink's receiver is in place.
  virtual void start(ros::NodeHandle nh) = 0;
  /// Messages (and pairs, lookups) refused so far, for the diagnostics (any thread).
  virtual std::uint64_t rejected() const = 0;
  /// Messages dropped as superseded so far: stamped at or before the latest accepted one of their
  /// topic (doc/boundary.md), not refusals (any thread).
  virtual std::uint64_t superseded() const { return 0; }
  /// What its inputs' one-publisher rule refused (any thread): the messages, and the receipt time
  /// (ns) of the latest, InputTimeline::kNone before one.
  virtual std::uint64_t foreignMessages() const { return 0; }
  virtual std::int64_t foreignHeard() const { return InputTimeline::kNone; }
  /// Times its inputs' timelines started afresh after refusing everything for their timeout.
  virtual std::uint64_t restarts() const { return 0; }
  /// The latest |t_target − t_self| of two samples combined (s); NaN when not applicable.
  virtual double skew() const { return std::numeric_limits<double>::quiet_NaN(); }
  /// The world frame and the world position (m) of the own controlled point; false when this
  /// input does not know it (the markers are then drawn at the follower's frame).
  virtual bool controlledPoint(std::string* /*frame*/, Eigen::Vector3d* /*point*/) { return false; }
};

/// The adapter that ~input names, or nullptr for "relative_measurement" (the subscription of
/// FollowerInputs itself).
/// @param axes of the model (1 to 3)
/// @throws ParameterError naming the key of an option the adapter refuses
std::unique_ptr<MeasurementAdapter> makeMeasurementAdapter(const std::string& node_name,
                                                           const FollowerNodeOptions& options,
                                                           int axes, MeasurementAdapter::Sink sink);

}  // namespace projection_collision_avoidance
