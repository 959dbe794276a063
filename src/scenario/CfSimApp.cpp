#include "projection_collision_avoidance/scenario/CfSimApp.hpp"

#include <chrono>
#include <cmath>
#include <cstddef>
#include <exception>
#include <filesystem>
#include <fstream>
#include <locale>
#include <memory>
#include <ostream>
#include <sstream>
#include <string>
#include <vector>

#include "projection_collision_avoidance/core/ParameterError.hpp"
#include "projection_collision_avoidance/scenario/ScenarioLoader.hpp"
#include "projection_collision_avoidance/sim/ContinuousSimulator.hpp"
#include "projection_collision_avoidance/sim/DisturbanceSweep.hpp"
#include "projection_collision_avoidance/sim/SampledSimulator.hpp"
#include "projection_collision_avoidance/sim/SimulationCsvWriter.hpp"
#include "projection_collision_avoidance/sim/StringStability.hpp"

namespace projection_collision_avoidance {
namespace {

constexpr const char* kUsage =
    "usage: cf_sim SCENARIO.yaml [--set key=value]... [--continuous STEP [--method rk4|rk6]]\n"
    "              [--csv FILE]\n"
    "       cf_sim SCENARIO.yaml [--set key=value]... --sweep FILE [--directions N]\n"
    "              [--max-size S] [--size-step S] [--tolerance S]";

constexpr double kDegreesPerRadian = 57.29577951308232;

struct Options {
  std::string scenario_path;
  std::vector<std::string> overrides;
  std::string csv_path;
  std::string sweep_path;
  SweepOptions sweep;
  double continuous_step = 0.0;  // s; > 0: simulateContinuous() at this step
  std::string method;            // "rk4" (default) or "rk6", with --continuous only
};

/// Parses a number option's value; false (with a message) if it is not one.
bool parseNumber(const std::string& option, const std::string& text, double* value,
                 std::ostream& err) {
  try {
    std::size_t consumed = 0;
    *value = std::stod(text, &consumed);
    if (consumed == text.size() && std::isfinite(*value)) {
      return true;
    }
  } catch (const std::exception&) {
  }
  err << "cf_sim: " << option << " needs a finite number, got '" << text << "'\n";
  return false;
}

bool parseOptions(const std::vector<std::string>& arguments, Options* options, std::ostream& err) {
  const std::vector<std::string> valued = {"--set",        "--csv",        "--sweep",
                                           "--directions", "--max-size",   "--size-step",
                                           "--tolerance",  "--continuous", "--method"};
  for (std::size_t i = 0; i < arguments.size(); ++i) {
    const std::string& argument = arguments[i];
    bool takes_value = false;
    for (const std::string& name : valued) {
      takes_value = takes_value || argument == name;
    }
    if (takes_value) {
      if (i + 1 >= arguments.size()) {
        err << "cf_sim: " << argument << " needs a value\n" << kUsage << "\n";
        return false;
      }
      const std::string& value = arguments[++i];
      double number = 0.0;
      if (argument == "--set") {
        options->overrides.push_back(value);
      } else if (argument == "--csv") {
        options->csv_path = value;
      } else if (argument == "--sweep") {
        options->sweep_path = value;
      } else if (argument == "--method") {
        if (value != "rk4" && value != "rk6") {
          err << "cf_sim: --method is rk4 or rk6, got '" << value << "'\n";
          return false;
        }
        options->method = value;
      } else if (!parseNumber(argument, value, &number, err)) {
        return false;
      } else if (argument == "--directions") {
        if (number != std::trunc(number) || std::abs(number) > 1e6) {
          err << "cf_sim: --directions needs a whole number, got '" << value << "'\n";
          return false;
        }
        options->sweep.directions = static_cast<int>(number);
      } else if (argument == "--continuous") {
        if (!(number > 0.0)) {
          err << "cf_sim: --continuous needs a step > 0 (s), got '" << value << "'\n";
          return false;
        }
        options->continuous_step = number;
      } else if (argument == "--max-size") {
        options->sweep.max_size = number;
      } else if (argument == "--size-step") {
        options->sweep.size_step = number;
      } else {
        options->sweep.tolerance = number;
      }
    } else if (argument == "-h" || argument == "--help") {
      err << kUsage << "\n";
      return false;
    } else if (!argument.empty() && argument[0] == '-') {
      err << "cf_sim: unknown option " << argument << "\n" << kUsage << "\n";
      return false;
    } else if (options->scenario_path.empty()) {
      options->scenario_path = argument;
    } else {
      err << "cf_sim: one scenario only\n" << kUsage << "\n";
      return false;
    }
  }
  if (options->scenario_path.empty()) {
    err << kUsage << "\n";
    return false;
  }
  if (!options->sweep_path.empty() && options->continuous_step > 0.0) {
    err << "cf_sim: --sweep and --continuous do not go together\n" << kUsage << "\n";
    return false;
  }
  if (!options->method.empty() && !(options->continuous_step > 0.0)) {
    err << "cf_sim: --method needs --continuous\n" << kUsage << "\n";
    return false;
  }
  if (!options->sweep_path.empty() && !options->csv_path.empty()) {
    err << "cf_sim: --sweep and --csv do not go together\n" << kUsage << "\n";
    return false;
  }
  return true;
}

/// FILE for one follower; FILE with "_<name>" before its extension in a formation.
std::string csvPathOf(const std::string& path, const FormationMember& member, bool formation) {
  if (!formation) {
    return path;
  }
  const std::filesystem::path original(path);
  std::filesystem::path result = original.parent_path();
  result /= original.stem().string() + "_" + member.name + original.extension().string();
  return result.string();
}

/// The first key set in @p scenario that only a sampled run models (the continuous-time loop
/// has no control period, and no link, headway, feed-forward shaping or barrier filter), or "".
std::string sampledOnlyKey(const Scenario& scenario) {
  const ControllerParameters& p = scenario.controller;
  const LinkSpec& link = scenario.link;
  const std::string sharing = "controller.leader_information.";
  if (std::isfinite(p.jerk_limit)) {
    return "controller.jerk_limit";
  }
  if (p.time_headway != 0.0) {
    return "controller.spacing.time_headway";
  }
  if (p.safety_filter) {
    return "controller.safety_filter";
  }
  if (p.feedforward_gain != 1.0) {
    return sharing + "feedforward.gain";
  }
  if (p.feedforward_time_constant != 0.0) {
    return sharing + "feedforward.time_constant";
  }
  if (link.configured && link.delay_periods != 0) {
    return sharing + "link.delay_periods";
  }
  if (link.configured && link.latency != 0.0) {
    return sharing + "link.latency";
  }
  if (link.configured && link.dropout != 0.0) {
    return sharing + "link.dropout";
  }
  return "";
}

/// Runs the scenario's formation (one follower without a formation section), writing the CSVs.
int runSimulation(const Scenario& scenario, const Options& options, std::ostream& out,
                  std::ostream& err) {
  const bool formation = scenario.formation.configured;
  const std::vector<FormationMember> members =
      layoutFormation(scenario.formation, scenario.controller.separation,
                      scenario.leader_initial_state, scenario.follower_initial_state);
  std::vector<std::string> csv_paths;
  std::vector<std::unique_ptr<std::ofstream>> csv_files;
  std::vector<std::unique_ptr<SimulationCsvWriter>> writers;
  if (!options.csv_path.empty()) {
    for (const FormationMember& member : members) {
      csv_paths.push_back(csvPathOf(options.csv_path, member, formation));
      csv_files.push_back(std::make_unique<std::ofstream>(csv_paths.back()));
      if (!*csv_files.back()) {
        err << "cf_sim: cannot write " << csv_paths.back() << "\n";
        return 3;
      }
      Scenario member_scenario = scenario;
      member_scenario.controller = memberParameters(scenario.controller, member);
      writers.push_back(std::make_unique<SimulationCsvWriter>(*csv_files.back(), member_scenario));
    }
  }
  FormationObserver observer;
  if (!writers.empty()) {
    observer = [&writers](int member, const SimulationSample& sample) {
      writers[static_cast<std::size_t>(member)]->write(sample);
    };
  }
  const auto start = std::chrono::steady_clock::now();
  FormationSummary summary;
  if (options.continuous_step > 0.0) {
    SampleObserver pair_observer;
    if (observer) {
      pair_observer = [&observer](const SimulationSample& sample) { observer(0, sample); };
    }
    const ContinuousMethod method =
        options.method == "rk6" ? ContinuousMethod::kRungeKutta6 : ContinuousMethod::kRungeKutta4;
    summary.followers.push_back(
        simulateContinuous(scenario, options.continuous_step, pair_observer, method));
  } else {
    summary = simulateFormation(scenario, observer);
  }
  const double wall =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  for (std::size_t i = 0; i < csv_files.size(); ++i) {
    csv_files[i]->flush();
    if (!*csv_files[i]) {
      err << "cf_sim: error writing " << csv_paths[i] << "\n";
      return 3;
    }
  }
  if (!formation) {
    out << formatSummary(summary.followers.front(), wall) << "\n";
    return 0;
  }
  for (std::size_t i = 0; i < members.size(); ++i) {
    out << members[i].name << " target=" << members[i].target_name << " "
        << formatSummary(summary.followers[i], wall) << "\n";
  }
  std::ostringstream last;
  last.imbue(std::locale::classic());
  last.precision(9);
  last << "formation followers=" << members.size()
       << " topology=" << toString(scenario.formation.topology)
       << " shape=" << toString(scenario.formation.shape)
       << " min_pair_separation=" << summary.min_pair_separation
       << " perimeter=" << summary.perimeter
       << " min_neighbour_separation=" << summary.min_neighbour_separation
       << " pairs_inside_perimeter=" << summary.pairs_inside_perimeter
       << " neighbour_pairs_inside_perimeter=" << summary.neighbour_pairs_inside_perimeter
       << " wall_s=" << wall;
  out << last.str() << "\n";
  const StringStabilityFigures figures = stringStabilityFigures(summary);
  std::ostringstream string_line;
  string_line.imbue(std::locale::classic());
  string_line.precision(9);
  string_line << "string_stability first_outside_bound=" << figures.first_outside_bound
              << " first_inside_perimeter=" << figures.first_inside_perimeter
              << " peak_ratio_max=" << figures.peak_ratio_max
              << " peak_growth=" << figures.peak_growth;
  out << string_line.str() << "\n";
  return 0;
}

/// Runs the disturbance sweep and writes its CSV.
int runSweep(const Scenario& scenario, const Options& options, std::ostream& out,
             std::ostream& err) {
  std::ofstream file(options.sweep_path);
  if (!file) {
    err << "cf_sim: cannot write " << options.sweep_path << "\n";
    return 3;
  }
  file.imbue(std::locale::classic());
  file.precision(9);
  file << "tracker,sharing,direction_deg,bound_limit,bound_capped,perimeter_limit,"
          "perimeter_capped\n";
  const auto start = std::chrono::steady_clock::now();
  long points = 0;
  sweepDisturbance(scenario, options.sweep, [&](const SweepPoint& point) {
    file << (point.configuration.tracker ? "on" : "off") << ','
         << toString(point.configuration.sharing) << ',' << point.direction * kDegreesPerRadian
         << ',' << point.bound_limit << ',' << (point.bound_capped ? 1 : 0) << ','
         << point.perimeter_limit << ',' << (point.perimeter_capped ? 1 : 0) << '\n';
    ++points;
  });
  file.flush();
  if (!file) {
    err << "cf_sim: error writing " << options.sweep_path << "\n";
    return 3;
  }
  const double wall =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  out << "sweep points=" << points << " wall_s=" << wall << "\n";
  return 0;
}

}  // namespace

int runCfSim(const std::vector<std::string>& arguments, std::ostream& out, std::ostream& err) {
  Options options;
  if (!parseOptions(arguments, &options, err)) {
    return 2;
  }
  try {
    const Scenario scenario = loadScenarioFile(options.scenario_path, options.overrides);
    const std::string unsupported =
        options.continuous_step > 0.0 ? sampledOnlyKey(scenario) : std::string();
    if (!unsupported.empty()) {
      err << "cf_sim: --continuous runs the continuous-time law, which has no control period: "
          << unsupported << " is not supported there (remove it, or run without --continuous)\n";
      return 2;
    }
    if (!options.sweep_path.empty()) {
      return runSweep(scenario, options, out, err);
    }
    return runSimulation(scenario, options, out, err);
  } catch (const ParameterError& error) {
    err << "cf_sim: invalid scenario: " << error.what() << "\n";
    return 1;
  }
}

}  // namespace projection_collision_avoidance
