#include "projection_collision_avoidance/configuration/ConfigurationLoader.hpp"

#include <string>
#include <vector>

#include <yaml-cpp/yaml.h>

#include "projection_collision_avoidance/core/ControllerDesign.hpp"

#include "ConfigurationSections.hpp"
#include "ControllerReader.hpp"
#include "YamlParser.hpp"
#include "YamlReader.hpp"

namespace projection_collision_avoidance {
namespace {

/// The sections a follower runs on; those of the simulation are marked known, not read.
FollowerConfiguration readConfiguration(const YAML::Node& root,
                                        const ConfigurationLoadOptions& options) {
  detail::YamlReader reader(root, "");
  FollowerConfiguration configuration;
  const AgentModel model = detail::readModel(reader);
  configuration.controller = detail::readController(reader, model);  // the link skipped
  for (const char* simulation_section : {"leader", "follower", "simulation", "world"}) {
    reader.skip(simulation_section);
  }
  configuration.formation = detail::readFormation(reader);
  reader.finish();

  configuration.formation.validate(model);
  configuration.formation.validateNeighbours(configuration.controller);
  if (options.check) {
    options.check(configuration);
  }
  ControllerDesign::create(configuration.controller);
  return configuration;
}

FollowerConfiguration readRoot(const YAML::Node& root, const std::vector<std::string>& overrides,
                               const ConfigurationLoadOptions& options) {
  return detail::readRoot(root, overrides,
                          [&](const YAML::Node& tree) { return readConfiguration(tree, options); });
}

}  // namespace

FollowerConfiguration followerConfigurationFromYaml(const YAML::Node& root,
                                                    const std::vector<std::string>& overrides,
                                                    const ConfigurationLoadOptions& options) {
  return readRoot(YAML::Clone(root), overrides, options);
}

FollowerConfiguration parseFollowerConfiguration(const std::string& yaml_text,
                                                 const std::vector<std::string>& overrides,
                                                 const ConfigurationLoadOptions& options) {
  return readRoot(detail::parseYaml(yaml_text, options.cancelled), overrides, options);
}

FollowerConfiguration loadFollowerConfigurationFile(const std::string& path,
                                                    const std::vector<std::string>& overrides,
                                                    const ConfigurationLoadOptions& options) {
  return parseFollowerConfiguration(detail::readYamlFile(path), overrides, options);
}

}  // namespace projection_collision_avoidance
