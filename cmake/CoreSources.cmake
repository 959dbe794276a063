# Source lists of the ROS-free libraries, relative to the repository root; shared by the
# package's CMakeLists.txt and the standalone sanitizer/fuzzer project
# (test/sanitize/CMakeLists.txt, which prefixes them with the root).

# projection_collision_avoidance_core: every equation of the controller (Eigen and std only).
set(PCA_CORE_SOURCES
  src/core/AgentIntegrator.cpp
  src/core/AgentModel.cpp
  src/core/ClosedLoopSimulator.cpp
  src/core/ContinuousSimulator.cpp
  src/core/ControllerDesign.cpp
  src/core/DisturbanceSweep.cpp
  src/core/ExactDiscretization.cpp
  src/core/FollowerController.cpp
  src/core/FollowerMode.cpp
  src/core/Formation.cpp
  src/core/LinearAlgebra.cpp
  src/core/PlatoonLaws.cpp
  src/core/RuntimeFollowerController.cpp
  src/core/Scenario.cpp
  src/core/ScenarioEmbedding.cpp
  src/core/SharedLink.cpp
  src/core/SignalProfile.cpp
  src/core/SimulationCsvWriter.cpp
  src/core/StringStability.cpp
)

# projection_collision_avoidance_scenario: scenario files (libyaml parses them into yaml-cpp
# trees) and the cf_sim command.
set(PCA_SCENARIO_SOURCES
  src/scenario/CfSimApp.cpp
  src/scenario/ControllerReader.cpp
  src/scenario/ScenarioLoader.cpp
  src/scenario/YamlParser.cpp
)
