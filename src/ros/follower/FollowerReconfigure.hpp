#pragma once

#include <memory>
#include <mutex>
#include <string>

#include <boost/thread/recursive_mutex.hpp>
#include <dynamic_reconfigure/server.h>
#include <ros/ros.h>

#include "projection_collision_avoidance/FollowerConfig.h"
#include "projection_collision_avoidance/core/ControllerParameters.hpp"
#include "projection_collision_avoidance/cycle/FollowerCycle.hpp"

#include "follower/FollowerOutputs.hpp"

namespace projection_collision_avoidance {

/// The follower's dynamic_reconfigure interface: tracker_enabled, alpha, epsilon,
/// tracker_natural_frequency and tracker_damping. Each accepted set becomes a new validated
/// design and controller, built here and handed to the control cycle (FollowerCycle::offer()),
/// which adopts it between two ticks. A frequency of 0 means the scenario file's tracker gain;
/// NaN, a negative frequency, or a set the design refuses is rejected (logged with its key) and
/// the configuration in force published back.
class FollowerReconfigure {
 public:
  /// @param file_design the design of this follower from the scenario (the frequency-0 gain),
  ///        the one the cycle starts with
  FollowerReconfigure(ros::NodeHandle private_nh, std::string node_name,
                      const ControllerDesign& file_design, FollowerCycle* cycle,
                      FollowerOutputs* outputs);

  /// Destroys the controller the cycle replaced last, if any (off the control thread).
  void collectRetired();

 private:
  void onReconfigure(FollowerConfig& config, uint32_t level);
  static FollowerConfig configOf(const ControllerParameters& parameters);

  std::string name_;
  ControllerParameters file_parameters_;
  ControllerDesign design_;  ///< in force: the last design built (the cycle's once adopted)
  FollowerCycle* cycle_;
  FollowerOutputs* outputs_;
  std::mutex mutex_;  ///< collectRetired() from the outputs' thread vs the callback
  FollowerConfig applied_;
  boost::recursive_mutex server_mutex_;
  dynamic_reconfigure::Server<FollowerConfig> server_;
};

}  // namespace projection_collision_avoidance
