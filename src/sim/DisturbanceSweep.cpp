#include "projection_collision_avoidance/sim/DisturbanceSweep.hpp"

#include <cmath>
#include <string>

#include "projection_collision_avoidance/core/ParameterError.hpp"
#include "projection_collision_avoidance/sim/SampledSimulator.hpp"

namespace projection_collision_avoidance {
namespace {

constexpr double kTwoPi = 6.283185307179586;

/// The verdicts of one run.
struct RunVerdict {
  bool bound_held = false;      ///< max ||xi|| <= xi_max
  bool perimeter_held = false;  ///< min separation >= perimeter
};

RunVerdict judge(const Scenario& base, const SweepConfiguration& configuration, double direction,
                 double size) {
  const SimulationSummary summary = simulate(sweepScenario(base, configuration, direction, size));
  return {summary.max_xi <= summary.xi_max, summary.min_separation >= summary.perimeter};
}

/// Refines a limit between a safe size and a failing one by bisection on one criterion.
template <typename Criterion>
double bisect(double safe, double failing, double tolerance, const Criterion& held) {
  while (failing - safe > tolerance) {
    const double middle = 0.5 * (safe + failing);
    if (held(middle)) {
      safe = middle;
    } else {
      failing = middle;
    }
  }
  return safe;
}

}  // namespace

std::string toString(LeaderSharing sharing) {
  switch (sharing) {
    case LeaderSharing::kCommand:
      return "command";
    case LeaderSharing::kEstimator:
      return "estimator";
    case LeaderSharing::kBoth:
      return "both";
    case LeaderSharing::kNone:
      break;
  }
  return "none";
}

void SweepOptions::validate() const {
  if (directions < 1 || directions > 3600) {
    throw ParameterError("sweep.directions",
                         "must lie in [1, 3600], got " + std::to_string(directions));
  }
  if (!(max_size > 0.0 && std::isfinite(max_size))) {
    throw ParameterError("sweep.max_size", "must be positive and finite");
  }
  if (!(size_step > 0.0 && size_step <= max_size)) {
    throw ParameterError("sweep.size_step", "must lie in (0, max_size]");
  }
  if (!(tolerance > 0.0 && tolerance <= size_step)) {
    throw ParameterError("sweep.tolerance", "must lie in (0, size_step]");
  }
  if (max_size / size_step > 1e5) {
    throw ParameterError("sweep.size_step", "gives more than 1e5 sizes per direction");
  }
}

std::vector<SweepConfiguration> sweepConfigurations() {
  std::vector<SweepConfiguration> configurations;
  for (const bool tracker : {false, true}) {
    for (const LeaderSharing sharing : {LeaderSharing::kNone, LeaderSharing::kCommand,
                                        LeaderSharing::kEstimator, LeaderSharing::kBoth}) {
      configurations.push_back({tracker, sharing});
    }
  }
  return configurations;
}

Scenario sweepScenario(const Scenario& base, const SweepConfiguration& configuration,
                       double direction, double size) {
  const AgentModel& model = base.controller.model;
  if (!model.isDoubleIntegrator()) {
    throw ParameterError("model.type", "the sweep needs a double_integrator model");
  }
  if (base.disturbance.pulses.size() != 1) {
    throw ParameterError("leader.disturbance",
                         "the sweep needs exactly one pulse, whose window it keeps");
  }
  if (base.formation.followers != 1) {
    throw ParameterError("formation.followers", "the sweep runs one follower");
  }
  if (base.formation.slots != SlotFrame::kWorld) {
    throw ParameterError("formation.slots", "the sweep runs the paper's world slot");
  }
  const int axes = model.double_integrator_axes;
  Scenario scenario = base;
  const Eigen::VectorXd r =
      base.controller.separation.head(axes) / base.controller.separation.head(axes).norm();
  Eigen::VectorXd& vector = scenario.disturbance.pulses.front().vector;
  vector.head(axes) = size * std::cos(direction) * r;
  vector.tail(axes) = size * std::sin(direction) * r;
  ControllerParameters& p = scenario.controller;
  p.tracker_enabled = configuration.tracker;
  const bool command = configuration.sharing == LeaderSharing::kCommand ||
                       configuration.sharing == LeaderSharing::kBoth;
  const bool estimator = configuration.sharing == LeaderSharing::kEstimator ||
                         configuration.sharing == LeaderSharing::kBoth;
  p.leader_input_in_command = command;
  p.leader_input_in_estimator = estimator;
  p.leader_disturbance_shared = command || estimator;
  if (!command) {  // a configuration that shares nothing into the command has nothing to shape
    p.feedforward_gain = 1.0;
    p.feedforward_time_constant = 0.0;
  }
  if (!command && !estimator) {  // nor a link to carry anything
    scenario.link = LinkSpec();
  }
  return scenario;
}

std::vector<SweepPoint> sweepDisturbance(const Scenario& base, const SweepOptions& options,
                                         const SweepProgress& progress) {
  options.validate();
  std::vector<SweepPoint> points;
  const long steps = std::lround(std::floor(options.max_size / options.size_step + 1e-9));
  for (const SweepConfiguration& configuration : sweepConfigurations()) {
    for (int j = 0; j < options.directions; ++j) {
      SweepPoint point;
      point.configuration = configuration;
      point.direction = kTwoPi * static_cast<double>(j) / options.directions;
      const auto run = [&](double size) {
        return judge(base, configuration, point.direction, size);
      };
      bool bound_found = false;
      bool perimeter_found = false;
      double previous = 0.0;
      for (long i = 1; i <= steps && !(bound_found && perimeter_found); ++i) {
        const double size = static_cast<double>(i) * options.size_step;
        const RunVerdict verdict = run(size);
        if (!bound_found && !verdict.bound_held) {
          bound_found = true;
          point.bound_limit = bisect(previous, size, options.tolerance,
                                     [&](double s) { return run(s).bound_held; });
        }
        if (!perimeter_found && !verdict.perimeter_held) {
          perimeter_found = true;
          point.perimeter_limit = bisect(previous, size, options.tolerance,
                                         [&](double s) { return run(s).perimeter_held; });
        }
        previous = size;
      }
      point.bound_capped = !bound_found;
      point.perimeter_capped = !perimeter_found;
      if (!bound_found) {
        point.bound_limit = previous;
      }
      if (!perimeter_found) {
        point.perimeter_limit = previous;
      }
      if (progress) {
        progress(point);
      }
      points.push_back(point);
    }
  }
  return points;
}

}  // namespace projection_collision_avoidance
