#include "ControllerReader.hpp"

#include <cmath>
#include <string>

#include <Eigen/Core>

#include "projection_collision_avoidance/core/ControllerDesign.hpp"
#include "projection_collision_avoidance/core/ParameterError.hpp"
#include "projection_collision_avoidance/core/PlatoonLaws.hpp"

namespace projection_collision_avoidance::detail {
namespace {

/// natural_frequency or damping: one value per axis (or one number for all), each positive.
void requirePositivePerAxis(const std::string& key, const Eigen::VectorXd& values, int axes) {
  if (values.size() != axes) {
    throw ParameterError(key, "must be one number or one per axis (" + std::to_string(axes) +
                                  "), got " + std::to_string(values.size()));
  }
  for (Eigen::Index i = 0; i < values.size(); ++i) {
    if (!(std::isfinite(values(i)) && values(i) > 0.0)) {
      throw ParameterError(key, "must be positive and finite, got " + std::to_string(values(i)));
    }
  }
}

Eigen::MatrixXd readGain(YamlReader& section, const AgentModel& model) {
  const bool matrix_form = section.has("gain");
  const bool pole_form = section.has("natural_frequency") || section.has("damping");
  if (matrix_form && pole_form) {
    throw ParameterError(section.key("gain"),
                         "give either gain or natural_frequency/damping, not both");
  }
  if (!pole_form) {
    return section.matrix("gain", model.inputDimension(), model.outputDimension());
  }
  if (!model.isDoubleIntegrator() || !model.C.isIdentity(0.0)) {
    throw ParameterError(section.key("natural_frequency"),
                         "needs a double_integrator model with C = identity; give gain instead");
  }
  const int axes = model.double_integrator_axes;
  const Eigen::VectorXd omega = section.vectorOrScalar("natural_frequency", axes);
  const Eigen::VectorXd zeta = section.vectorOrScalar("damping", axes);
  requirePositivePerAxis(section.key("natural_frequency"), omega, axes);
  requirePositivePerAxis(section.key("damping"), zeta, axes);
  return doubleIntegratorGain(omega, zeta, section.key("natural_frequency"));
}

}  // namespace

ControllerParameters readController(YamlReader& reader, const AgentModel& model,
                                    const LinkSectionReader& read_link) {
  const Eigen::Index n = model.stateDimension();
  const Eigen::Index m = model.inputDimension();
  const Eigen::Index p = model.outputDimension();
  YamlReader controller = reader.map("controller");
  ControllerParameters result;
  result.model = model;
  result.control_rate = controller.number("control_rate");
  result.separation = controller.vector("separation");
  result.alpha = controller.number("alpha");
  result.epsilon = controller.number("epsilon");

  YamlReader baseline = controller.map("baseline");
  result.baseline_gain = readGain(baseline, model);
  baseline.finish();

  YamlReader estimator = controller.map("estimator");
  result.estimator_gain = estimator.matrix("gain", n, p);
  result.lyapunov_weight = estimator.matrix("lyapunov_weight", n, n);
  if (estimator.has("substeps")) {
    result.estimator_substeps = estimator.integer("substeps");
  }
  if (estimator.has("initial_estimate")) {
    const std::string mode = estimator.string("initial_estimate");
    if (mode == "measurement") {
      result.initial_estimate = InitialEstimate::kMeasurement;
    } else if (mode == "zero") {
      result.initial_estimate = InitialEstimate::kZero;
    } else {
      throw ParameterError(estimator.key("initial_estimate"),
                           "must be measurement or zero, got '" + mode + "'");
    }
  }
  estimator.finish();

  YamlReader tracker = controller.map("tracker");
  result.tracker_enabled = tracker.boolean("enabled");
  result.tracker_gain = readGain(tracker, model);
  result.reference_gain = tracker.has("reference_gain") ? tracker.matrix("reference_gain", m, p)
                                                        : Eigen::MatrixXd::Zero(m, p);
  tracker.finish();

  if (controller.has("acceleration_limit")) {
    result.acceleration_limit = controller.number("acceleration_limit");
  }
  if (controller.has("jerk_limit")) {
    result.jerk_limit = controller.number("jerk_limit");
  }
  if (controller.has("fallback")) {
    YamlReader fallback = controller.map("fallback");
    if (fallback.has("gain") && fallback.has("velocity_gain")) {
      throw ParameterError(fallback.key("gain"), "give gain or velocity_gain, not both");
    }
    if (fallback.has("gain")) {
      result.fallback_gain = fallback.matrix("gain", m, n);
    } else if (fallback.has("velocity_gain")) {
      if (!model.isDoubleIntegrator()) {
        throw ParameterError(fallback.key("velocity_gain"),
                             "needs a double_integrator model; give gain instead");
      }
      result.fallback_gain = doubleIntegratorFallbackGain(model.double_integrator_axes,
                                                          fallback.number("velocity_gain"));
    }
    fallback.finish();
  }
  if (controller.has("leader_information")) {
    YamlReader sharing = controller.map("leader_information");
    if (sharing.has("command")) {
      result.leader_input_in_command = sharing.boolean("command");
    }
    if (sharing.has("estimator")) {
      result.leader_input_in_estimator = sharing.boolean("estimator");
    }
    if (sharing.has("disturbance")) {
      result.leader_disturbance_shared = sharing.boolean("disturbance");
    }
    if (sharing.has("feedforward")) {
      YamlReader feedforward = sharing.map("feedforward");
      if (feedforward.has("gain")) {
        result.feedforward_gain = feedforward.number("gain");
      }
      if (feedforward.has("time_constant")) {
        result.feedforward_time_constant = feedforward.number("time_constant");
      }
      feedforward.finish();
    }
    if (sharing.has("link") && read_link) {
      read_link(sharing);
    }
    sharing.finish();
  }
  if (controller.has("spacing")) {
    YamlReader spacing = controller.map("spacing");
    if (spacing.has("time_headway")) {
      result.time_headway = spacing.number("time_headway");
    }
    spacing.finish();
  }
  if (controller.has("safety_filter")) {
    YamlReader filter = controller.map("safety_filter");
    SafetyFilterParameters parameters;
    if (filter.has("rate")) {
      parameters.rate = filter.number("rate");
    }
    filter.finish();
    parameters.validate(controller.key("safety_filter"));
    if (result.tracker_enabled) {
      throw ParameterError(tracker.key("enabled"),
                           "must be false with controller.safety_filter: the barrier filter's "
                           "nominal command is the baseline law");
    }
    if (!model.isDoubleIntegrator()) {
      throw ParameterError(controller.key("safety_filter"),
                           "needs a double_integrator model (the barrier (B1) is on positions)");
    }
    result.safety_filter = parameters;
  }
  controller.finish();
  validatePlatoonParameters(result);  // the new keys' own checks, before any derived one
  return result;
}

}  // namespace projection_collision_avoidance::detail
