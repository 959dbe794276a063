#include "plant/PlantWorld.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <sstream>
#include <utility>

#include <boost/make_shared.hpp>
#include <geometry_msgs/TransformStamped.h>
#include <nav_msgs/Odometry.h>
#include <ros/master.h>
#include <rosgraph_msgs/Clock.h>
#include <tf2_eigen/tf2_eigen.h>
#include <visualization_msgs/MarkerArray.h>

#include "projection_collision_avoidance/core/Formation.hpp"
#include "projection_collision_avoidance/core/ParameterError.hpp"
#include "projection_collision_avoidance/cycle/FrameNames.hpp"
#include "projection_collision_avoidance/ros/MessageConversions.hpp"
#include "projection_collision_avoidance/ros/ScenarioParameters.hpp"

namespace projection_collision_avoidance {
namespace {

/// Markers are published at most this often (Hz of simulated time).
constexpr double kMarkerRate = 20.0;
/// Wall seconds between the last tick's messages and the shutdown, to let them out.
constexpr double kShutdownDelay = 0.25;
/// Wall seconds between two queries of the master for ~wait_for_subscribers.
constexpr double kTopicPollPeriod = 0.05;

}  // namespace

PlantWorld::Agent::Agent(const std::string& agent_name, const std::string& tf_frame,
                         const AgentModel& model, double step, const Eigen::VectorXd& initial_state,
                         const SignalProfile& disturbance, double command_timeout,
                         const StampCorrectionOptions& clock_skew)
    : name(agent_name),
      frame(tf_frame),
      integrator(model, step, initial_state, disturbance),
      command(Eigen::VectorXd::Zero(model.inputDimension())),
      // A command stamped ahead of the plant's time by more than the command timeout would never
      // time out: its sender's clock is not the plant's (a wall-time stamp under simulated
      // time, say). Jumps back of the plant's time come from its clock (PlantClock's hook).
      // The frame is judged in onCommand(): the agent's or the world's.
      command_timeline(agent_name + "/command",
                       {{"", command_timeout, command_timeout}, clock_skew, false}) {}

PlantWorld::PlantWorld(ros::NodeHandle nh, ros::NodeHandle private_nh)
    : nh_(nh),
      name_(ros::this_node::getName()),
      scenario_(loadDoubleIntegratorScenario(private_nh)),
      reader_(private_nh),
      options_(readPlantOptions(reader_, scenario_)),
      axes_(scenario_.controller.model.double_integrator_axes),
      leader_("leader", options_.leader_frame, scenario_.controller.model, 1.0 / options_.rate,
              scenario_.leader_initial_state, scenario_.disturbance, options_.command_timeout,
              options_.clock_skew) {
  echoScenario(name_, private_nh);
  reader_.echo(name_);

  // The followers of the formation. Subscriptions hold pointers into the list, so it is complete
  // before any is made.
  const std::vector<FormationMember> members =
      layoutFormation(scenario_.formation, scenario_.controller.separation,
                      scenario_.leader_initial_state, scenario_.follower_initial_state);
  followers_.reserve(members.size());
  for (const FormationMember& member : members) {
    const std::string frame =
        scenario_.formation.configured ? member.name : options_.follower_frame;
    if (frame == options_.world_frame || frame == options_.leader_frame) {
      throw ParameterError(
          scenario_.formation.configured ? "~scenario/formation" : "~follower_frame",
          "follower frame '" + frame + "' clashes with the world or leader frame");
    }
    // The world as cf_sim applies it (nothing without a world section), the true vehicle's lag
    // sampled at the plant's step: the control period when ~rate is the control rate. The gusts
    // are drawn up to the plant's own end when it runs longer than the scenario's duration (the
    // same gusts as cf_sim's over that duration, and more after it).
    FollowerWorld world(scenario_.world, member.index, scenario_.controller.model,
                        std::max(scenario_.duration, options_.duration), 1.0 / options_.rate);
    const SignalProfile disturbance = world.disturbance();
    followers_.push_back(Follower{
        Agent(member.name, frame, scenario_.controller.model, 1.0 / options_.rate,
              member.initial_state, disturbance, options_.command_timeout, options_.clock_skew),
        member.target,
        {},
        std::move(world),
        {}});
  }
  attachVehicle(&leader_);
  if (leader_.vehicle &&
      (!scenario_.disturbance.pulses.empty() || scenario_.disturbance.hasSinusoids())) {
    ROS_WARN_STREAM(name_ << ": the leader is a vehicle kind: leader.disturbance does not act");
  }
  connectAgent(&leader_);
  for (std::size_t i = 0; i < followers_.size(); ++i) {
    Follower& follower = followers_[i];
    attachVehicle(&follower.agent);
    if (follower.agent.vehicle && (follower.world.disturbed() || follower.world.hasVehicle())) {
      ROS_WARN_STREAM(name_ << ": " << follower.agent.name
                            << " is a vehicle kind: the world's disturbance and true vehicle do "
                               "not act on it");
    }
    connectAgent(&follower.agent);
    follower.measurement_publisher.advertise<RelativeMeasurement>(
        nh_, follower.agent.name + "/relative_measurement", 10);
    if (scenario_.formation.neighbours.enabled) {
      advertiseNeighbours(static_cast<int>(i));
    }
  }
  if (scenario_.formation.neighbours.enabled) {
    states_.assign(1 + followers_.size(), Eigen::VectorXd::Zero(2 * axes_));
  }
  marker_publisher_ = nh_.advertise<visualization_msgs::MarkerArray>("agent_markers", 2);
  ticks_per_marker_ = std::max(1L, static_cast<long>(std::ceil(options_.rate / kMarkerRate)));
  if (options_.duration > 0.0) {
    last_tick_ = std::lround(options_.duration * options_.rate);
  }
  channels_ = std::make_unique<MeasurementChannels>(static_cast<int>(followers_.size()), axes_,
                                                    options_.rate, options_.faults);
  if (options_.publish_clock) {
    if (!ros::Time::isSimTime()) {
      ROS_WARN_STREAM(name_ << ": ~publish_clock is set but /use_sim_time is not: the other "
                               "nodes will ignore /clock");
    }
    clock_publisher_ = nh_.advertise<rosgraph_msgs::Clock>("/clock", 10);
  }
  // The clock's timers run their callbacks under mutex_: none before clock_ is set.
  const std::lock_guard<std::mutex> lock(mutex_);
  PlantClock::Hooks hooks;
  hooks.tick = [this](long k) { return tick(k); };
  hooks.stop = [this](const std::string& why) { stop(why); };
  hooks.jump = [this](double /*jump*/) {
    // A restarted /clock: commands of the new timeline are judged afresh.
    const auto restart = [](Agent& agent) {
      agent.command_timeline.restart();
      if (agent.vehicle) {
        agent.vehicle->restartTimeline();
      }
    };
    restart(leader_);
    for (Follower& follower : followers_) {
      restart(follower.agent);
    }
  };
  for (const std::string& topic : options_.wait_for_subscribers) {
    waited_topics_.push_back(nh_.resolveName(topic));
  }
  hooks.listening = [this] {
    int listening = 0;
    for (const Follower& follower : followers_) {
      // A vehicle's follower listens to odometry and drives it through cmd_vel.
      const PlantVehicle* vehicle = follower.agent.vehicle.get();
      // A double integrator's follower takes its relative_measurement, or its odometry
      // (~input odometry).
      const bool listens = vehicle != nullptr ? vehicle->driven()
                                              : follower.measurement_publisher.subscribed() ||
                                                    follower.agent.odom_publisher.subscribed();
      listening += listens ? 1 : 0;
    }
    return std::make_pair(listening + subscribedWaitedTopics(),
                          static_cast<int>(followers_.size() + waited_topics_.size()));
  };
  hooks.answered = [this](long k) { return commandsAnswer(k); };
  hooks.all_commanded = [this] { return everyAgentCommanded(); };
  hooks.before_tick = [this] { command_queue_.callAvailable(); };
  clock_ = std::make_unique<PlantClock>(nh_, name_, options_, &mutex_, std::move(hooks));
  std::ostringstream summary;
  summary << name_ << ": simulating a leader and " << followers_.size() << " follower(s)";
  if (scenario_.formation.configured) {
    summary << " (" << toString(scenario_.formation.topology) << ", "
            << toString(scenario_.formation.shape) << ")";
  }
  summary << ", " << axes_ << " axes, at " << options_.rate << " Hz";
  if (options_.publish_clock) {
    summary << ", publishing /clock at " << options_.real_time_factor << "x real time";
  } else {
    summary << " on ROS time";
  }
  if (options_.duration > 0.0) {
    summary << ", for " << options_.duration << " s";
  }
  ROS_INFO_STREAM(summary.str());
}

int PlantWorld::subscribedWaitedTopics() {
  if (waited_topics_.empty()) {
    return 0;
  }
  // The master's registrations, at most every kTopicPollPeriod (the wait polls far faster).
  const ros::WallTime now = ros::WallTime::now();
  if (!topics_polled_.isZero() && (now - topics_polled_).toSec() < kTopicPollPeriod) {
    return subscribed_topics_;
  }
  topics_polled_ = now;
  XmlRpc::XmlRpcValue request;
  XmlRpc::XmlRpcValue response;
  XmlRpc::XmlRpcValue state;
  request[0] = name_;
  if (!ros::master::execute("getSystemState", request, response, state, false) ||
      state.getType() != XmlRpc::XmlRpcValue::TypeArray || state.size() < 2 ||
      state[1].getType() != XmlRpc::XmlRpcValue::TypeArray) {
    return subscribed_topics_;  // no answer: as before
  }
  // state[1]: the subscriptions, [[topic, [node, ...]], ...].
  int subscribed = 0;
  for (const std::string& topic : waited_topics_) {
    for (int i = 0; i < state[1].size(); ++i) {
      XmlRpc::XmlRpcValue& entry = state[1][i];
      if (entry.getType() == XmlRpc::XmlRpcValue::TypeArray && entry.size() == 2 &&
          entry[0].getType() == XmlRpc::XmlRpcValue::TypeString &&
          static_cast<std::string>(entry[0]) == topic &&
          entry[1].getType() == XmlRpc::XmlRpcValue::TypeArray && entry[1].size() > 0) {
        ++subscribed;
        break;
      }
    }
  }
  subscribed_topics_ = subscribed;
  return subscribed;
}

void PlantWorld::attachVehicle(Agent* agent) {
  const auto found = options_.vehicles.find(agent->name);
  if (found == options_.vehicles.end() || found->second.kind == VehicleKind::kDoubleIntegrator) {
    return;
  }
  agent->vehicle = std::make_unique<PlantVehicle>(
      found->second,
      PlantVehicle::Setup{name_, agent->name, agent->frame, options_.world_frame, axes_,
                          options_.command_timeout, options_.clock_skew},
      agent->integrator.state());
  ROS_INFO_STREAM(name_ << ": " << agent->name << " is a " << toString(found->second.kind)
                        << " vehicle: commands on " << agent->name << "/cmd_vel");
}

void PlantWorld::connectAgent(Agent* agent) {
  if (agent->vehicle) {
    agent->vehicle->connect(nh_, &mutex_, [this] { return plantNow(); });
    geometry_msgs::TransformStamped odom_frame;
    if (agent->vehicle->odomFrameTransform(plantNow(), &odom_frame)) {
      static_broadcaster_.sendTransform(odom_frame);  // latched: one per vehicle, kept
    }
    if (options_.lockstep) {
      agent->controller_subscriber =
          subscribeCommand(agent, [this, agent](const CommandEvent& event) {
            const std::lock_guard<std::mutex> lock(mutex_);
            agent->controller_stamp =
                std::max(agent->controller_stamp, nanosecondsOf(event.getMessage()->header.stamp));
          });
    }
    return;
  }
  agent->odom_publisher.advertise<nav_msgs::Odometry>(nh_, agent->name + "/odom", 10);
  agent->applied_command_publisher.advertise<geometry_msgs::AccelStamped>(
      nh_, agent->name + "/applied_command", 10);
  agent->command_subscriber = subscribeCommand(
      agent, [this, agent](const CommandEvent& event) { onCommand(agent, event); });
}

ros::Subscriber PlantWorld::subscribeCommand(
    Agent* agent, const boost::function<void(const CommandEvent&)>& callback) {
  return subscribeEvents<geometry_msgs::AccelStamped>(
      nh_, agent->name + "/command", 10, callback, ros::TransportHints().tcpNoDelay(),
      PlantClock::ticksOnThread(options_) ? &command_queue_ : nullptr);
}

void PlantWorld::onCommand(Agent* agent, const CommandEvent& event) {
  const geometry_msgs::AccelStamped::ConstPtr& msg = event.getConstMessage();
  const std::lock_guard<std::mutex> lock(mutex_);
  InputTimeline& timeline = agent->command_timeline;
  admitGuarded(timeline, name_, [&] {
    // In the world frame (a follower names the frame of its measurements, the plant's world) or
    // the agent's (a leader, or a follower that knows no world frame): the same axes here.
    if (!sameFrame(msg->header.frame_id, agent->frame) &&
        !sameFrame(msg->header.frame_id, options_.world_frame)) {
      timeline.reject(Rejection::kFrame,
                      "frame_id '" +
                          boundedText(msg->header.frame_id, InputGuard::kMaxQuotedLength) +
                          "', expected '" + agent->frame + "' or '" + options_.world_frame + "'");
      return;
    }
    // Judged on the sender's clock, its order on the raw stamps and its age against the plant's
    // time moved by the offset of ~clock_skew/policy (0 by default), as the follower does.
    if (!checkHeader(timeline, msg->header, plantNow(), publisherOf(event))) {
      return;
    }
    std::string why;
    Eigen::VectorXd command;
    if (!commandFromAccelMsg(*msg, axes_, &command, &why)) {
      timeline.reject(Rejection::kContent, why);
      return;
    }
    if (!timeline.guard().everAccepted()) {
      ROS_INFO_STREAM(name_ << ": first " << agent->name << "/command received");
    }
    agent->command = command;
    timeline.accept();  // on the plant's clock, never before the previous one
  });
}

void PlantWorld::stop(const std::string& why) {
  ROS_INFO_STREAM(name_ << ": " << why << "; shutting down");
  clock_->halt();
  // Shut down a moment later (wall time), so that the last tick's messages reach subscribers.
  shutdown_timer_ = nh_.createWallTimer(
      ros::WallDuration(kShutdownDelay), [](const ros::WallTimerEvent&) { ros::requestShutdown(); },
      true);
}

}  // namespace projection_collision_avoidance
