# Source lists of the ROS-free libraries, relative to the repository root; shared by the
# package's CMakeLists.txt and the standalone sanitizer/fuzzer project
# (test/sanitize/CMakeLists.txt, which prefixes them with the root).

# projection_collision_avoidance_core: the controller, every law of the paper (Eigen and std only).
set(PCA_CORE_SOURCES
  src/core/AgentModel.cpp
  src/core/CommandProjection.cpp
  src/core/ControllerDesign.cpp
  src/core/ConvoyReference.cpp
  src/core/DynamicFollowerController.cpp
  src/core/ExactDiscretization.cpp
  src/core/FollowerController.cpp
  src/core/FollowerMode.cpp
  src/core/Formation.cpp
  src/core/LinearAlgebra.cpp
  src/core/NeighbourBarrier.cpp
  src/core/PlatoonLaws.cpp
  src/core/SafetyFilter.cpp
  src/core/TargetPath.cpp
  src/core/TurningSlot.cpp
)

# projection_collision_avoidance_sim: simulation and experiment tooling around the controller
# (the plant, the sampled and continuous loops, sweeps, the measurement channel and the link of
# shared information, the simulated velocity-controlled and unicycle vehicles); Eigen and std only.
set(PCA_SIM_SOURCES
  src/sim/AgentIntegrator.cpp
  src/sim/ContinuousSimulator.cpp
  src/sim/DisturbanceSweep.cpp
  src/sim/MeasurementChannel.cpp
  src/sim/SampledSimulator.cpp
  src/sim/Scenario.cpp
  src/sim/ScenarioEmbedding.cpp
  src/sim/SharedLink.cpp
  src/sim/SignalProfile.cpp
  src/sim/SimulationCsvWriter.cpp
  src/sim/StringStability.cpp
  src/sim/VehicleModels.cpp
  src/sim/WorldSpec.cpp
)

# projection_collision_avoidance_configuration: a follower's configuration (the model, controller
# and formation sections of a scenario file; libyaml parses the file into a yaml-cpp tree); the
# core and the YAML libraries only.
set(PCA_CONFIGURATION_SOURCES
  src/configuration/ConfigurationLoader.cpp
  src/configuration/ConfigurationSections.cpp
  src/configuration/ControllerReader.cpp
  src/configuration/YamlParser.cpp
)

# projection_collision_avoidance_scenario: whole scenario files (the simulation's sections too,
# read with the configuration library's) and the cf_sim command.
set(PCA_SCENARIO_SOURCES
  src/scenario/CfSimApp.cpp
  src/scenario/ScenarioLoader.cpp
  src/scenario/ScenarioSections.cpp
)

# projection_collision_avoidance_vehicle: the vehicle adapters' math (odometry pairs to a relative
# state, the unicycle's look-ahead point, velocity commands, the output timeout); Eigen and std.
set(PCA_VEHICLE_SOURCES
  src/vehicle/CommandConverter.cpp
  src/vehicle/CommandHistory.cpp
  src/vehicle/OutputWatchdog.cpp
  src/vehicle/RelativeStateFromOdometry.cpp
  src/vehicle/RelativeVelocityFilter.cpp
  src/vehicle/Rotation.cpp
  src/vehicle/UnicycleLookAhead.cpp
  src/vehicle/VehicleResponseEstimator.cpp
  src/vehicle/VelocityCommandIntegrator.cpp
)
