#include "projection_collision_avoidance/ros/FollowerNode.hpp"

#include <cmath>
#include <sstream>
#include <system_error>

#include "projection_collision_avoidance/core/ControllerDesign.hpp"
#include "projection_collision_avoidance/core/DynamicFollowerController.hpp"
#include "projection_collision_avoidance/core/ParameterError.hpp"
#include "projection_collision_avoidance/cycle/FollowerCycle.hpp"
#include "projection_collision_avoidance/ros/RosParameters.hpp"

#include "follower/FollowerInputs.hpp"
#include "follower/FollowerLoop.hpp"
#include "follower/FollowerOptions.hpp"
#include "follower/FollowerOutputs.hpp"
#include "follower/FollowerReconfigure.hpp"
#include "follower/MeasurementAdapter.hpp"
#include "follower/MeasurementTrigger.hpp"

namespace projection_collision_avoidance {

FollowerNode::FollowerNode(ros::NodeHandle nh, ros::NodeHandle private_nh)
    : FollowerNode(nh, private_nh, loadFollowerConfiguration(private_nh)) {}

FollowerNode::FollowerNode(ros::NodeHandle nh, ros::NodeHandle private_nh,
                           const FollowerConfiguration& configuration) {
  NodeOptionReader reader(private_nh);
  const FormationMember member = memberOf(reader, configuration);
  const ControllerParameters parameters = memberParameters(configuration.controller, member);
  auto controller =
      std::make_unique<DynamicFollowerController>(ControllerDesign::create(parameters));
  const ControllerDesign& design = controller->design();
  FollowerNodeOptions options =
      readFollowerOptions(reader, parameters, member, ros::Time::isSimTime());
  if (configuration.formation.slots == SlotFrame::kTurning) {
    options.turning = configuration.formation.turning;
  }
  if (configuration.formation.slots == SlotFrame::kPath) {
    if (options.trigger == ControlTrigger::kMeasurement) {
      throw ParameterError("~trigger",
                           "must be timer with formation.slots: path (the reference "
                           "moves one control period per step)");
    }
    options.path = configuration.formation.path;
  }
  options.agent_name = member.name;
  options.target_name = member.target_name;
  if (configuration.formation.neighbours.enabled) {
    // rho: formation.neighbours.perimeter, else alpha ||d|| of the scenario's d (as cf_sim).
    const double perimeter = configuration.formation.neighbours.perimeter;
    options.neighbours = NeighbourCycleSettings{
        configuration.formation.neighbours,
        std::isnan(perimeter) ? ControllerDesign::create(configuration.controller).perimeter
                              : perimeter};
  }
  if (options.lock_memory) {
    try {
      lockProcessMemory();
    } catch (const std::system_error& error) {
      throw ParameterError(
          "~lock_memory",
          "is true but mlockall(MCL_CURRENT | MCL_FUTURE) failed: " + error.code().message() +
              " (needs root or CAP_IPC_LOCK, or an RLIMIT_MEMLOCK above the "
              "process's size)");
    }
  }
  const std::string name = private_nh.getNamespace();
  echoScenario(name, private_nh);
  reader.echo(name);

  FollowerCycleSettings settings;
  settings.measurement_timeout = options.measurement_timeout;
  settings.leader_timeout = options.leader_timeout;
  settings.use_leader_input = options.use_leader_broadcast;
  settings.measurement_trigger = options.trigger == ControlTrigger::kMeasurement;
  settings.turning = options.turning;
  settings.path = options.path;
  settings.neighbours = options.neighbours;
  const ControllerDesign start = design;
  cycle_ = std::make_unique<FollowerCycle>(std::move(controller), parameters.separation, settings);
  try {
    // The inputs subscribe once the outputs that a measurement's step uses are in place.
    FollowerInputs::AcceptedSink on_accepted;
    if (options.trigger == ControlTrigger::kMeasurement) {
      on_accepted = [this](std::uint32_t skipped) { trigger_->onAccepted(skipped); };
    }
    inputs_ = std::make_unique<FollowerInputs>(name, options, start, cycle_.get(),
                                               std::move(on_accepted));
    outputs_ =
        std::make_unique<FollowerOutputs>(nh, private_nh, name, options, parameters.control_rate,
                                          member, parameters.separation, inputs_.get());
    trigger_ = std::make_unique<MeasurementTrigger>(cycle_.get(), outputs_.get());
    inputs_->start(nh);
    input_adapter_ = makeMeasurementAdapter(
        name, options, parameters.model.double_integrator_axes,
        [this](const RelativeMeasurement& msg) { inputs_->admitMeasurement(msg); });
    if (input_adapter_) {
      inputs_->setAdapter(input_adapter_.get());
      outputs_->setMarkerOrigin([this](std::string* frame, Eigen::Vector3d* origin) {
        return input_adapter_->controlledPoint(frame, origin);
      });
      input_adapter_->start(nh);
    }
    reconfigure_ = std::make_unique<FollowerReconfigure>(private_nh, name, start, cycle_.get(),
                                                         outputs_.get());
    if (options.control_loop == ControlLoop::kThread) {
      outputs_->startThread([this] { reconfigure_->collectRetired(); });
    }
    // "tick" and the formation index: each follower's tick thread by name, even in one manager.
    loop_ =
        std::make_unique<FollowerLoop>(nh, name, "tick " + std::to_string(member.index), options,
                                       parameters.control_rate, cycle_.get(), outputs_.get());
  } catch (...) {
    stop();  // the parts already running, in the order the destructor stops them
    throw;
  }

  std::ostringstream loop;
  if (options.control_loop == ControlLoop::kThread) {
    loop << ", control loop: thread"
         << (options.control_priority > 0
                 ? ", SCHED_FIFO " + std::to_string(options.control_priority)
                 : std::string());
  }
  if (options.lock_memory) {
    loop << ", memory locked";
  }
  ROS_INFO_STREAM(
      name << ": " << member.name << " looking at " << member.target_name << ", d = ["
           << parameters.separation.transpose() << "], running at " << parameters.control_rate
           << " Hz (input: " << toString(options.input)
           << ", trigger: " << toString(options.trigger) << loop.str() << "), "
           << parameters.model.double_integrator_axes << " axes, xi_max " << start.xi_max << " m"
           << (parameters.time_headway > 0.0
                   ? ", time headway " + std::to_string(parameters.time_headway) + " s from " +
                         inputs_->odometryTopic()
                   : std::string())
           << (options.turning ? ", turning slot (heading from " + inputs_->odometryTopic() +
                                     " and the measurement)"
                               : std::string())
           << (options.path ? ", path slot (the target's path from " + inputs_->odometryTopic() +
                                  " and the measurement)"
                            : std::string())
           << (options.neighbours
                   ? ", keeping out of every agent of " + inputs_->neighboursTopic() +
                         " (perimeter " + std::to_string(options.neighbours->perimeter) + " m)"
                   : std::string()));
}

FollowerNode::~FollowerNode() { stop(); }

void FollowerNode::stop() {
  loop_.reset();  // "thread": ends within one period (at most 10 ms) and a tick
  if (outputs_) {
    outputs_->stopThread();
  }
  reconfigure_.reset();
  if (inputs_) {
    inputs_->setAdapter(nullptr);
  }
  input_adapter_.reset();
  inputs_.reset();  // no measurement's step after this
  trigger_.reset();
  outputs_.reset();
}

}  // namespace projection_collision_avoidance
