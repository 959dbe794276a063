#include "follower/FollowerReconfigure.hpp"

#include <cmath>
#include <utility>

#include "projection_collision_avoidance/core/ControllerDesign.hpp"
#include "projection_collision_avoidance/core/DynamicFollowerController.hpp"
#include "projection_collision_avoidance/core/ParameterError.hpp"
#include "projection_collision_avoidance/ros/RosParameters.hpp"

namespace projection_collision_avoidance {

FollowerReconfigure::FollowerReconfigure(ros::NodeHandle private_nh, std::string node_name,
                                         const ControllerDesign& file_design, FollowerCycle* cycle,
                                         FollowerOutputs* outputs)
    : name_(std::move(node_name)),
      file_parameters_(file_design.parameters),
      design_(file_design),
      cycle_(cycle),
      outputs_(outputs),
      server_(server_mutex_, private_nh) {
  outputs_->describeTrackerGain(design_.parameters.tracker_gain);
  applied_ = configOf(design_.parameters);
  server_.updateConfig(applied_);
  server_.setCallback(
      [this](FollowerConfig& config, uint32_t level) { onReconfigure(config, level); });
}

FollowerConfig FollowerReconfigure::configOf(const ControllerParameters& parameters) {
  FollowerConfig config;
  config.tracker_enabled = parameters.tracker_enabled;
  config.alpha = parameters.alpha;
  config.epsilon = parameters.epsilon;
  config.tracker_natural_frequency = 0.0;  // 0 keeps the configured G_e matrix
  config.tracker_damping = 0.7;
  return config;
}

void FollowerReconfigure::collectRetired() {
  const std::lock_guard<std::mutex> lock(mutex_);
  cycle_->retired().reset();
}

void FollowerReconfigure::onReconfigure(FollowerConfig& config, uint32_t /*level*/) {
  const std::lock_guard<std::mutex> lock(mutex_);
  cycle_->retired().reset();
  ControllerParameters candidate = design_.parameters;
  candidate.tracker_enabled = config.tracker_enabled;
  candidate.alpha = config.alpha;
  candidate.epsilon = config.epsilon;
  try {
    for (const auto& [name, value] :
         {std::pair<const char*, double>{"alpha", config.alpha},
          {"epsilon", config.epsilon},
          {"tracker_natural_frequency", config.tracker_natural_frequency},
          {"tracker_damping", config.tracker_damping}}) {
      if (!std::isfinite(value)) {
        throw ParameterError(name, "must be finite, got " + std::to_string(value));
      }
    }
    if (candidate.tracker_enabled && candidate.safety_filter) {
      throw ParameterError("tracker_enabled",
                           "must be false with controller.safety_filter (the barrier filter's "
                           "nominal command is the baseline law)");
    }
    if (config.tracker_natural_frequency < 0.0) {
      throw ParameterError("tracker_natural_frequency",
                           "must be >= 0 (0: the scenario's gain), got " +
                               std::to_string(config.tracker_natural_frequency));
    }
    if (config.tracker_natural_frequency > 0.0) {
      if (!candidate.model.C.isIdentity(0.0)) {
        throw ParameterError("tracker_natural_frequency", "needs C = identity");
      }
      const int axes = candidate.model.double_integrator_axes;
      candidate.tracker_gain = doubleIntegratorGain(
          Eigen::VectorXd::Constant(axes, config.tracker_natural_frequency),
          Eigen::VectorXd::Constant(axes, config.tracker_damping), "tracker_natural_frequency");
    } else {
      candidate.tracker_gain = file_parameters_.tracker_gain;  // 0: the scenario file's gain
    }
    auto controller =
        std::make_unique<DynamicFollowerController>(ControllerDesign::create(candidate));
    design_ = controller->design();
    cycle_->offer(std::move(controller)).reset();  // an offer not yet adopted is superseded
    outputs_->describeTrackerGain(design_.parameters.tracker_gain);
    ROS_INFO_STREAM(name_ << ": reconfigured: tracker "
                          << (candidate.tracker_enabled ? "on" : "off") << ", alpha "
                          << candidate.alpha << ", epsilon " << candidate.epsilon
                          << ", tracker gain "
                          << (config.tracker_natural_frequency > 0.0 ? "from the frequency"
                                                                     : "of the scenario file")
                          << ", xi_max " << design_.xi_max << " m");
    applied_ = config;
  } catch (const ParameterError& error) {
    ROS_ERROR_STREAM(name_ << ": reconfiguration refused, previous values kept: " << error.what());
    config = applied_;
  }
}

}  // namespace projection_collision_avoidance
