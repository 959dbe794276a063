#include "projection_collision_avoidance/CfSimApp.hpp"

#include <chrono>
#include <cstddef>
#include <fstream>
#include <memory>
#include <ostream>
#include <string>
#include <vector>

#include "projection_collision_avoidance/ClosedLoopSimulator.hpp"
#include "projection_collision_avoidance/ParameterError.hpp"
#include "projection_collision_avoidance/ScenarioLoader.hpp"
#include "projection_collision_avoidance/SimulationCsvWriter.hpp"

namespace projection_collision_avoidance {
namespace {

constexpr const char* kUsage = "usage: cf_sim SCENARIO.yaml [--set key=value]... [--csv FILE]";

struct Options {
  std::string scenario_path;
  std::vector<std::string> overrides;
  std::string csv_path;
};

bool parseOptions(const std::vector<std::string>& arguments, Options* options, std::ostream& err) {
  for (std::size_t i = 0; i < arguments.size(); ++i) {
    const std::string& argument = arguments[i];
    if (argument == "--set" || argument == "--csv") {
      if (i + 1 >= arguments.size()) {
        err << "cf_sim: " << argument << " needs a value\n" << kUsage << "\n";
        return false;
      }
      ++i;
      if (argument == "--set") {
        options->overrides.push_back(arguments[i]);
      } else {
        options->csv_path = arguments[i];
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
  return true;
}

}  // namespace

int runCfSim(const std::vector<std::string>& arguments, std::ostream& out, std::ostream& err) {
  Options options;
  if (!parseOptions(arguments, &options, err)) {
    return 2;
  }
  try {
    const Scenario scenario = loadScenarioFile(options.scenario_path, options.overrides);
    std::ofstream csv_file;
    std::unique_ptr<SimulationCsvWriter> csv;
    if (!options.csv_path.empty()) {
      csv_file.open(options.csv_path);
      if (!csv_file) {
        err << "cf_sim: cannot write " << options.csv_path << "\n";
        return 3;
      }
      csv = std::make_unique<SimulationCsvWriter>(csv_file, scenario);
    }
    SampleObserver observer;
    if (csv) {
      observer = [&csv](const SimulationSample& sample) { csv->write(sample); };
    }
    const auto start = std::chrono::steady_clock::now();
    const SimulationSummary summary = simulate(scenario, observer);
    const double wall =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (csv) {
      csv_file.flush();
      if (!csv_file) {
        err << "cf_sim: error writing " << options.csv_path << "\n";
        return 3;
      }
    }
    out << formatSummary(summary, wall) << "\n";
    return 0;
  } catch (const ParameterError& error) {
    err << "cf_sim: invalid scenario: " << error.what() << "\n";
    return 1;
  }
}

}  // namespace projection_collision_avoidance
