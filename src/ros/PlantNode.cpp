#include "projection_collision_avoidance/ros/PlantNode.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <utility>

#include <geometry_msgs/TransformStamped.h>
#include <nav_msgs/Odometry.h>
#include <rosgraph_msgs/Clock.h>
#include <tf2_eigen/tf2_eigen.h>
#include <visualization_msgs/MarkerArray.h>

#include "projection_collision_avoidance/Formation.hpp"
#include "projection_collision_avoidance/ParameterError.hpp"
#include "projection_collision_avoidance/ros/MessageConversions.hpp"

namespace projection_collision_avoidance {
namespace {

/// Markers are published at most this often (Hz of simulated time).
constexpr double kMarkerRate = 20.0;
/// A tick is due when the time is within this fraction of a period of it.
constexpr double kTickTolerance = 1e-6;
/// Wall seconds of ticks that one wall-timer callback may catch up.
constexpr double kMaxCatchUp = 0.05;
/// Wall seconds between the last tick's messages and the shutdown, to let them out.
constexpr double kShutdownDelay = 0.25;

std::string frameParameter(NodeOptionReader& reader, const std::string& key,
                           const std::string& fallback) {
  const std::string frame = reader.text(key, fallback);
  if (frame.empty()) {
    throw ParameterError("~" + key, "must not be empty");
  }
  return frame;
}

PlantNodeOptions readOptions(NodeOptionReader& reader, const Scenario& scenario) {
  PlantNodeOptions o;
  o.rate = reader.number("rate", scenario.controller.control_rate, 1.0, 10000.0);
  o.world_frame = frameParameter(reader, "world_frame", o.world_frame);
  o.leader_frame = frameParameter(reader, "leader_frame", o.leader_frame);
  o.follower_frame = frameParameter(reader, "follower_frame", o.follower_frame);
  if (o.leader_frame == o.world_frame || o.follower_frame == o.world_frame) {
    throw ParameterError(o.leader_frame == o.world_frame ? "~leader_frame" : "~follower_frame",
                         "must differ from ~world_frame '" + o.world_frame + "'");
  }
  if (o.follower_frame == o.leader_frame) {
    throw ParameterError("~follower_frame",
                         "must differ from ~leader_frame '" + o.leader_frame + "'");
  }
  o.noise_position = reader.number("measurement_noise_position", 0.0, 0.0, 1000.0);
  o.noise_velocity = reader.number("measurement_noise_velocity", 0.0, 0.0, 1000.0);
  o.dropout = reader.number("measurement_dropout", 0.0, 0.0, 1.0);
  if (o.dropout >= 1.0) {
    throw ParameterError("~measurement_dropout",
                         "must lie in [0, 1), got " + std::to_string(o.dropout));
  }
  o.latency = reader.number("measurement_latency", 0.0, 0.0, 1.0);
  o.outage_start = reader.number("measurement_outage_start", 0.0, 0.0, 1e7);
  o.outage_duration = reader.number("measurement_outage_duration", 0.0, 0.0, 1e7);
  o.noise_seed = reader.integer("noise_seed", 1, 0, std::numeric_limits<int>::max());
  o.command_timeout = reader.number("command_timeout", o.command_timeout, 0.0, 3600.0);
  if (o.command_timeout <= 0.0) {
    throw ParameterError("~command_timeout",
                         "must be > 0, got " + std::to_string(o.command_timeout));
  }
  o.publish_clock = reader.boolean("publish_clock", false);
  o.real_time_factor = reader.number("real_time_factor", 1.0, 0.0, 1000.0);
  if (o.real_time_factor <= 0.0) {
    throw ParameterError("~real_time_factor",
                         "must lie in (0, 1000], got " + std::to_string(o.real_time_factor));
  }
  o.duration = reader.number("duration", 0.0, 0.0, 1e7);
  o.wait_for_followers = reader.number("wait_for_followers", 0.0, 0.0, 3600.0);
  o.lockstep = reader.boolean("lockstep", false);
  o.lockstep_timeout = reader.number("lockstep_timeout", o.lockstep_timeout, 0.001, 3600.0);
  if (o.lockstep && !o.publish_clock) {
    throw ParameterError("~lockstep",
                         "is true but ~publish_clock is false: only a plant that drives "
                         "simulated time can wait for the commands");
  }
  return o;
}

visualization_msgs::Marker labelMarker(const std::string& frame, const ros::Time& stamp, int id,
                                       const std::string& text, double height) {
  visualization_msgs::Marker marker =
      toMarker(frame, stamp, "labels", id, visualization_msgs::Marker::TEXT_VIEW_FACING,
               Eigen::Vector3d(0.0, 0.0, height), 0.3, MarkerColor{});
  marker.scale.x = marker.scale.y = 0.0;
  marker.text = text;
  return marker;
}

}  // namespace

PlantNode::Agent::Agent(const std::string& agent_name, const std::string& tf_frame,
                        const AgentModel& model, double step, const Eigen::VectorXd& initial_state,
                        const SignalProfile& disturbance, double command_timeout)
    : name(agent_name),
      frame(tf_frame),
      integrator(model, step, initial_state, disturbance),
      command(Eigen::VectorXd::Zero(model.inputDimension())),
      command_guard(agent_name + "/command", {tf_frame, command_timeout, command_timeout}) {}

PlantNode::PlantNode(ros::NodeHandle nh, ros::NodeHandle private_nh)
    : nh_(nh),
      name_(ros::this_node::getName()),
      scenario_(loadDoubleIntegratorScenario(private_nh)),
      reader_(private_nh),
      options_(readOptions(reader_, scenario_)),
      axes_(scenario_.controller.model.double_integrator_axes),
      leader_("leader", options_.leader_frame, scenario_.controller.model, 1.0 / options_.rate,
              scenario_.leader_initial_state, scenario_.disturbance, options_.command_timeout),
      rng_(static_cast<std::mt19937::result_type>(options_.noise_seed)) {
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
    followers_.push_back(
        Follower{Agent(member.name, frame, scenario_.controller.model, 1.0 / options_.rate,
                       member.initial_state, SignalProfile{}, options_.command_timeout),
                 member.target,
                 {},
                 {},
                 0,
                 false});
  }
  leader_.odom_publisher = nh_.advertise<nav_msgs::Odometry>("leader/odom", 10);
  leader_.applied_command_publisher =
      nh_.advertise<geometry_msgs::AccelStamped>("leader/applied_command", 10);
  leader_.command_subscriber = nh_.subscribe<geometry_msgs::AccelStamped>(
      "leader/command", 10,
      [this](const geometry_msgs::AccelStamped::ConstPtr& msg) { onCommand(&leader_, msg); },
      ros::VoidConstPtr(), ros::TransportHints().tcpNoDelay());
  for (Follower& follower : followers_) {
    Agent* agent = &follower.agent;
    agent->odom_publisher = nh_.advertise<nav_msgs::Odometry>(agent->name + "/odom", 10);
    agent->applied_command_publisher =
        nh_.advertise<geometry_msgs::AccelStamped>(agent->name + "/applied_command", 10);
    follower.measurement_publisher =
        nh_.advertise<RelativeMeasurement>(agent->name + "/relative_measurement", 10);
    agent->command_subscriber = nh_.subscribe<geometry_msgs::AccelStamped>(
        agent->name + "/command", 10,
        [this, agent](const geometry_msgs::AccelStamped::ConstPtr& msg) { onCommand(agent, msg); },
        ros::VoidConstPtr(), ros::TransportHints().tcpNoDelay());
  }
  marker_publisher_ = nh_.advertise<visualization_msgs::MarkerArray>("agent_markers", 2);
  ticks_per_marker_ = std::max(1L, static_cast<long>(std::ceil(options_.rate / kMarkerRate)));
  if (options_.duration > 0.0) {
    last_tick_ = std::lround(options_.duration * options_.rate);
  }

  if (options_.publish_clock) {
    // The plant owns simulated time: it must not wait on ROS time (which stays 0 under
    // use_sim_time until a /clock arrives), so it ticks on wall time and publishes /clock.
    if (!ros::Time::isSimTime()) {
      ROS_WARN_STREAM(name_ << ": ~publish_clock is set but /use_sim_time is not: the other "
                               "nodes will ignore /clock");
    }
    clock_publisher_ = nh_.advertise<rosgraph_msgs::Clock>("/clock", 10);
    started_ = true;
    origin_ = ros::Time(0);
    wall_origin_ = ros::WallTime::now();
    rate_check_wall_ = wall_origin_;
    waiting_for_followers_ = options_.wait_for_followers > 0.0;
    wall_timer_ =
        nh_.createWallTimer(ros::WallDuration(1.0 / (options_.rate * options_.real_time_factor)),
                            &PlantNode::onWallTick, this);
  } else {
    timer_ = nh_.createTimer(ros::Duration(1.0 / options_.rate), &PlantNode::onRosTick, this);
  }
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

void PlantNode::onCommand(Agent* agent, const geometry_msgs::AccelStamped::ConstPtr& msg) {
  const std::lock_guard<std::mutex> lock(mutex_);
  // A command stamped ahead of the plant's time by more than ~command_timeout would never time
  // out: its sender's clock is not the plant's (a wall-time stamp under simulated time, say).
  admitGuarded(agent->command_guard, name_, [&] {
    const ros::Time now = started_ ? stampOf(std::max(0L, next_tick_ - 1)) : ros::Time::now();
    if (!checkHeader(agent->command_guard, msg->header, now)) {
      return;
    }
    std::string why;
    Eigen::VectorXd command;
    if (!commandFromAccelMsg(*msg, axes_, &command, &why)) {
      agent->command_guard.reject(Rejection::kContent, why);
      return;
    }
    if (!agent->command_guard.everAccepted()) {
      ROS_INFO_STREAM(name_ << ": first " << agent->name << "/command received");
    }
    agent->command = command;
    agent->command_guard.accept(nanosecondsOf(msg->header.stamp), nanosecondsOf(now));
  });
}

ros::Time PlantNode::stampOf(long k) const {
  const double offset_ns = static_cast<double>(k) * 1e9 / options_.rate;
  ros::Time stamp;
  stamp.fromNSec(origin_.toNSec() + static_cast<uint64_t>(std::llround(offset_ns)));
  return stamp;
}

void PlantNode::onWallTick(const ros::WallTimerEvent& /*event*/) {
  const std::lock_guard<std::mutex> lock(mutex_);
  if (!running_) {
    return;
  }
  // Tick k is due at wall time wall_origin_ + k / (rate * real_time_factor). A callback that
  // runs late catches up the ticks due since (at most kMaxCatchUp s of them at once), so that
  // simulated time keeps the real-time factor on average; a backlog beyond that is dropped
  // (simulated time slows down) and reported below.
  const double wall_rate = options_.rate * options_.real_time_factor;
  const ros::WallTime now = ros::WallTime::now();
  if (waiting_for_followers_) {
    // Simulated time starts once every follower listens, or ~wait_for_followers s after start.
    int listening = 0;
    for (const Follower& follower : followers_) {
      listening += follower.measurement_publisher.getNumSubscribers() > 0 ? 1 : 0;
    }
    const double waited = (now - wall_origin_).toSec();
    const bool all = listening == static_cast<int>(followers_.size());
    if (!all && waited < options_.wait_for_followers) {
      return;
    }
    waiting_for_followers_ = false;
    if (all) {
      ROS_INFO_STREAM(name_ << ": every follower listens after " << waited
                            << " s: simulated time starts");
    } else {
      ROS_WARN_STREAM(name_ << ": " << listening << " of " << followers_.size()
                            << " followers listen after ~wait_for_followers = " << waited
                            << " s: simulated time starts without the others");
    }
    wall_origin_ = now;
    rate_check_wall_ = now;
  }
  long due =
      static_cast<long>(std::floor((now - wall_origin_).toSec() * wall_rate + kTickTolerance));
  const long max_catch_up = std::max(1L, std::lround(kMaxCatchUp * wall_rate));
  if (due - next_tick_ >= max_catch_up) {
    due = next_tick_;
    wall_origin_ = now - ros::WallDuration(static_cast<double>(next_tick_) / wall_rate);
  }
  while (running_ && next_tick_ <= due) {
    if (options_.lockstep && next_tick_ > 0 && !commandsAnswer(next_tick_ - 1)) {
      if (!holding_) {
        holding_ = true;
        hold_start_ = now;
      }
      if ((now - hold_start_).toSec() < options_.lockstep_timeout) {
        // Simulated time waits: the wall schedule restarts from here.
        wall_origin_ = now - ros::WallDuration(static_cast<double>(next_tick_) / wall_rate);
        break;
      }
      ++lockstep_timeouts_;
      ROS_WARN_STREAM_THROTTLE(5.0, name_ << ": lockstep: tick " << next_tick_ << " waited "
                                          << options_.lockstep_timeout
                                          << " s for the commands and runs without them ("
                                          << lockstep_timeouts_ << " such ticks)");
    }
    holding_ = false;
    running_ = tick(next_tick_);
    ++next_tick_;
  }
  // Report, at most every 5 s, a simulation slower than the real-time factor asked for.
  const double wall = (now - rate_check_wall_).toSec();
  if (wall >= 5.0) {
    const double factor = static_cast<double>(next_tick_ - rate_check_tick_) / options_.rate / wall;
    if (factor < 0.9 * options_.real_time_factor) {
      ROS_WARN_STREAM(name_ << ": simulating at " << factor << "x real time, below the "
                            << options_.real_time_factor << "x asked for");
    }
    rate_check_wall_ = now;
    rate_check_tick_ = next_tick_;
  }
}

void PlantNode::onRosTick(const ros::TimerEvent& /*event*/) {
  const std::lock_guard<std::mutex> lock(mutex_);
  try {
    rosTick();
  } catch (const std::exception& error) {
    ROS_ERROR_STREAM_THROTTLE(5.0, name_ << ": tick failed: " << error.what());
  }
}

void PlantNode::rosTick() {
  const ros::Time now = ros::Time::now();
  if (!running_ || now.isZero()) {
    return;
  }
  if (clock_.wentBack(now)) {
    // A restarted /clock: commands of the new timeline are judged afresh.
    ROS_WARN_STREAM(name_ << ": ROS time went back by " << -clock_.jump() << " s, to "
                          << now.toSec() << " s; waiting for it to reach "
                          << stampOf(next_tick_).toSec() << " s again");
    leader_.command_guard.restartTimeline();
    for (Follower& follower : followers_) {
      follower.agent.command_guard.restartTimeline();
    }
  }
  if (!started_) {
    // Under use_sim_time scenario time is ROS time; otherwise it starts at the first tick.
    started_ = true;
    origin_ = ros::Time::isSimTime() ? ros::Time(0) : now;
    next_tick_ =
        static_cast<long>(std::ceil(secondsBetween(now, origin_) * options_.rate - kTickTolerance));
    if (last_tick_ >= 0 && next_tick_ > last_tick_) {
      std::ostringstream why;
      why << "ROS time " << now.toSec() << " s is already past ~duration = " << options_.duration
          << " s";
      stop(why.str());
      return;
    }
  }
  const long due =
      static_cast<long>(std::floor(secondsBetween(now, origin_) * options_.rate + kTickTolerance));
  if (due < next_tick_ - 1) {
    return;  // ROS time went back: wait for it to reach the next tick again
  }
  // Catch up every due tick, at most one second of them per call.
  const long limit = next_tick_ + std::max(1L, std::lround(options_.rate));
  while (running_ && next_tick_ <= std::min(due, limit)) {
    running_ = tick(next_tick_);
    ++next_tick_;
  }
}

bool PlantNode::tick(long k) {
  if (options_.lockstep && k > 0) {
    advanceAll(k - 1);  // [t_k-1, t_k] with the commands that answered sample k - 1
  }
  const ros::Time stamp = stampOf(k);

  // Sample: odometry, tf, relative measurements.
  const Eigen::VectorXd leader_state = leader_.integrator.state();
  std::vector<geometry_msgs::TransformStamped> transforms;
  transforms.reserve(1 + followers_.size());
  leader_.odom_publisher.publish(
      toOdometryMsg(leader_state, stamp, options_.world_frame, leader_.frame));
  transforms.push_back(
      toTransformMsg(leader_state.head(axes_), stamp, options_.world_frame, leader_.frame));
  for (Follower& follower : followers_) {
    const Eigen::VectorXd state = follower.agent.integrator.state();
    follower.agent.odom_publisher.publish(
        toOdometryMsg(state, stamp, options_.world_frame, follower.agent.frame));
    transforms.push_back(
        toTransformMsg(state.head(axes_), stamp, options_.world_frame, follower.agent.frame));
    publishMeasurement(&follower, k, stamp);
  }
  tf_broadcaster_.sendTransform(transforms);
  if (k % ticks_per_marker_ == 0) {
    publishMarkers(stamp);
  }
  if (options_.publish_clock) {
    rosgraph_msgs::Clock clock;
    clock.clock = stamp;
    clock_publisher_.publish(clock);
  }
  if (last_tick_ >= 0 && k >= last_tick_) {
    std::ostringstream why;
    why << "simulated time reached ~duration = " << options_.duration << " s";
    stop(why.str());
    return false;
  }

  if (!options_.lockstep) {
    advanceAll(k);  // in lockstep tick k + 1 does it, once the answers to sample k are in
  }
  return true;
}

void PlantNode::advanceAll(long k) {
  const double t = static_cast<double>(k) / options_.rate;
  const ros::Time stamp = stampOf(k);
  advanceAgent(&leader_, t, stamp);
  for (Follower& follower : followers_) {
    advanceAgent(&follower.agent, t, stamp);
  }
}

bool PlantNode::commandsAnswer(long k) const {
  const std::int64_t due = nanosecondsOf(stampOf(k));
  const auto answered = [due](const Agent& agent) {
    return !agent.command_guard.haveAccepted() || agent.command_guard.lastStamp() >= due;
  };
  if (!answered(leader_)) {
    return false;
  }
  return std::all_of(followers_.begin(), followers_.end(),
                     [&](const Follower& follower) { return answered(follower.agent); });
}

void PlantNode::advanceAgent(Agent* agent, double t, const ros::Time& stamp) {
  const GenericDimensions::InputVector command = commandAt(agent, stamp);
  agent->applied_command_publisher.publish(toAccelMsg(command, stamp, agent->frame));
  agent->integrator.advance(t, command);
}

void PlantNode::publishMeasurement(Follower* follower, long k, const ros::Time& stamp) {
  // Draw every random number every tick, so the noise sequence does not depend on dropouts.
  Eigen::VectorXd noise(2 * axes_);
  for (int i = 0; i < 2 * axes_; ++i) {
    noise(i) = normal_(rng_) * (i < axes_ ? options_.noise_position : options_.noise_velocity);
  }
  const bool dropped = uniform_(rng_) < options_.dropout;
  const double t = static_cast<double>(k) / options_.rate;
  const bool in_outage = options_.outage_duration > 0.0 && t >= options_.outage_start &&
                         t < options_.outage_start + options_.outage_duration;
  if (in_outage) {
    if (!follower->in_outage) {
      ROS_WARN_STREAM(name_ << ": " << follower->agent.name << "/relative_measurement outage for "
                            << options_.outage_duration << " s from t = " << t << " s");
    }
  } else if (follower->in_outage) {
    ROS_INFO_STREAM(name_ << ": " << follower->agent.name
                          << "/relative_measurement outage over at t = " << t << " s");
  }
  follower->in_outage = in_outage;
  if (in_outage) {
    // Nothing sampled; what was sampled before still arrives after its latency.
  } else if (dropped) {
    ++follower->dropped;
  } else {
    const Eigen::VectorXd relative =
        targetOf(*follower).integrator.state() - follower->agent.integrator.state() + noise;
    follower->pending.push_back(toRelativeMeasurementMsg(relative, stamp, options_.world_frame));
  }
  // Publish what was sampled at least `latency` ago (in ticks, t_k - t_j >= latency).
  const double latency_ticks = options_.latency * options_.rate;
  while (!follower->pending.empty()) {
    const RelativeMeasurement& oldest = follower->pending.front();
    const double sampled_tick = secondsBetween(oldest.header.stamp, origin_) * options_.rate;
    if (static_cast<double>(k) - sampled_tick < latency_ticks - kTickTolerance) {
      break;
    }
    follower->measurement_publisher.publish(oldest);
    follower->pending.pop_front();
  }
}

const PlantNode::Agent& PlantNode::targetOf(const Follower& follower) const {
  return follower.target == 0 ? leader_
                              : followers_[static_cast<std::size_t>(follower.target - 1)].agent;
}

void PlantNode::publishMarkers(const ros::Time& stamp) {
  using visualization_msgs::Marker;
  visualization_msgs::MarkerArray markers;
  markers.markers.push_back(toMarker(leader_.frame, stamp, "agents", 0, Marker::CUBE,
                                     Eigen::Vector3d::Zero(), 0.6, {0.1F, 0.3F, 1.0F, 1.0F}));
  markers.markers.push_back(labelMarker(leader_.frame, stamp, 0, leader_.name, 0.7));
  // Who looks at whom: a thin grey line from each follower to its target, in the world frame.
  Marker links = toMarker(options_.world_frame, stamp, "links", 0, Marker::LINE_LIST,
                          Eigen::Vector3d::Zero(), 0.04, {0.6F, 0.6F, 0.6F, 0.8F});
  int id = 1;
  for (const Follower& follower : followers_) {
    markers.markers.push_back(toMarker(follower.agent.frame, stamp, "agents", id, Marker::SPHERE,
                                       Eigen::Vector3d::Zero(), 0.5, {1.0F, 0.55F, 0.0F, 1.0F}));
    markers.markers.push_back(
        labelMarker(follower.agent.frame, stamp, id, follower.agent.name, 0.6));
    for (const Agent* end : {&follower.agent, &targetOf(follower)}) {
      links.points.push_back(tf2::toMsg(toVector3(end->integrator.state().head(axes_))));
    }
    ++id;
  }
  markers.markers.push_back(links);
  marker_publisher_.publish(markers);
}

GenericDimensions::InputVector PlantNode::commandAt(Agent* agent, const ros::Time& now) {
  const InputGuard& guard = agent->command_guard;
  const bool fresh = guard.haveAccepted() &&
                     std::abs(1e-9 * static_cast<double>(nanosecondsOf(now) - guard.lastStamp())) <=
                         options_.command_timeout;
  if (fresh) {
    if (agent->command_timed_out) {
      ROS_INFO_STREAM(name_ << ": " << agent->name << "/command fresh again");
      agent->command_timed_out = false;
    }
    return agent->command;
  }
  if (guard.haveAccepted() && !agent->command_timed_out) {
    ROS_WARN_STREAM(name_ << ": " << agent->name << "/command stamped "
                          << 1e-9 * static_cast<double>(guard.lastStamp())
                          << " s is older than ~command_timeout (" << options_.command_timeout
                          << " s) at " << now.toSec() << " s: using zero");
    agent->command_timed_out = true;
  }
  return GenericDimensions::InputVector::Zero(axes_);
}

void PlantNode::stop(const std::string& why) {
  ROS_INFO_STREAM(name_ << ": " << why << "; shutting down");
  running_ = false;
  wall_timer_.stop();
  timer_.stop();
  // Shut down a moment later (wall time), so that the last tick's messages reach subscribers.
  shutdown_timer_ = nh_.createWallTimer(
      ros::WallDuration(kShutdownDelay), [](const ros::WallTimerEvent&) { ros::requestShutdown(); },
      true);
}

}  // namespace projection_collision_avoidance
