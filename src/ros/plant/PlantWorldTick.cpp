/// PlantWorld's ticks: the agents advanced over one period, what each tick publishes, and the
/// commands the agents apply (PlantWorld.cpp builds and connects the world).

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <utility>

#include <geometry_msgs/TransformStamped.h>
#include <nav_msgs/Odometry.h>
#include <rosgraph_msgs/Clock.h>
#include <tf2_eigen/tf2_eigen.h>
#include <visualization_msgs/MarkerArray.h>

#include "projection_collision_avoidance/ros/MessageConversions.hpp"

#include "plant/PlantWorld.hpp"

namespace projection_collision_avoidance {

bool PlantWorld::tick(long k) {
  if (options_.lockstep && k > 0) {
    advanceAll(k - 1);  // [t_k-1, t_k] with the commands that answered sample k - 1
  }
  const ros::Time stamp = clock_->stampOf(k);

  // formation.neighbours: each follower's sensed agents first, so that a follower that steps on
  // its measurement finds the array of the same tick when the two reach it in the order sent.
  if (!states_.empty()) {
    const auto store = [](const Agent& agent, Eigen::VectorXd* state) {
      if (agent.vehicle) {
        *state = agent.vehicle->state();
      } else {
        *state = agent.integrator.state();  // into the vector of last tick: no allocation
      }
    };
    store(leader_, &states_[0]);
    for (std::size_t i = 0; i < followers_.size(); ++i) {
      store(followers_[i].agent, &states_[i + 1]);
    }
    for (std::size_t i = 0; i < followers_.size(); ++i) {
      publishNeighbours(static_cast<int>(i), stamp);
    }
  }
  // Sample: odometry, tf, relative measurements.
  std::vector<geometry_msgs::TransformStamped> transforms;
  transforms.reserve(1 + followers_.size());
  sampleAgent(&leader_, stamp, &transforms);
  for (std::size_t i = 0; i < followers_.size(); ++i) {
    sampleAgent(&followers_[i].agent, stamp, &transforms);
    publishMeasurement(static_cast<int>(i), k);
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

void PlantWorld::sampleAgent(Agent* agent, const ros::Time& stamp,
                             std::vector<geometry_msgs::TransformStamped>* transforms) {
  if (agent->vehicle) {
    agent->vehicle->publishSample(stamp, transforms);
    return;
  }
  const Eigen::VectorXd state = agent->integrator.state();
  // Shared pointers: a subscriber in the same process (nodelets) gets the message itself.
  if (agent->odom_publisher.subscribed()) {
    agent->odom_publisher.publish(boost::make_shared<nav_msgs::Odometry>(
        toOdometryMsg(state, stamp, options_.world_frame, agent->frame)));
  }
  transforms->push_back(
      toTransformMsg(state.head(axes_), stamp, options_.world_frame, agent->frame));
}

void PlantWorld::advanceAll(long k) {
  const double t = static_cast<double>(k) / options_.rate;
  const ros::Time stamp = clock_->stampOf(k);
  advanceAgent(&leader_, t, stamp);
  for (Follower& follower : followers_) {
    advanceAgent(&follower.agent, t, stamp, &follower.world);
  }
}

bool PlantWorld::commandsAnswer(long k) const {
  const ros::Time due_time = clock_->stampOf(k);
  const std::int64_t due = nanosecondsOf(due_time);
  // Waited for: an agent that has commanded and still has a sender (one that was stopped, or
  // whose node ended, holds nobody up); it answers with a command stamped at t_k or later (a
  // vehicle's Twist carries no stamp: one received after sample k went out; and the controller
  // behind its adapter, when there is one, with a command stamped at t_k or later).
  const auto answered = [due, &due_time](const Agent& agent) {
    if (agent.vehicle) {
      return agent.vehicle->answered(due_time) &&
             (agent.controller_stamp < 0 || agent.controller_subscriber.getNumPublishers() == 0 ||
              agent.controller_stamp >= due);
    }
    return !agent.command_timeline.guard().haveAccepted() ||
           agent.command_subscriber.getNumPublishers() == 0 ||
           agent.command_timeline.stamp() >= due;
  };
  return answered(leader_) &&
         std::all_of(followers_.begin(), followers_.end(),
                     [&](const Follower& follower) { return answered(follower.agent); });
}

bool PlantWorld::everyAgentCommanded() const {
  const auto commanded = [](const Agent& agent) {
    if (agent.vehicle) {
      return agent.vehicle->commanded();
    }
    return agent.command_timeline.guard().haveAccepted() ||
           agent.command_subscriber.getNumPublishers() == 0;
  };
  return commanded(leader_) &&
         std::all_of(followers_.begin(), followers_.end(),
                     [&](const Follower& follower) { return commanded(follower.agent); });
}

void PlantWorld::advanceAgent(Agent* agent, double t, const ros::Time& stamp,
                              FollowerWorld* world) {
  if (agent->vehicle) {
    agent->vehicle->advance(1.0 / options_.rate, stamp);
    return;
  }
  GenericDimensions::InputVector command = commandAt(agent, stamp);
  if (world != nullptr && world->hasVehicle()) {
    command = world->apply(command);  // g z_k of its true vehicle, as SampledSimulator applies it
  }
  if (agent->applied_command_publisher.subscribed()) {
    agent->applied_command_publisher.publish(
        boost::make_shared<geometry_msgs::AccelStamped>(toAccelMsg(command, stamp, agent->frame)));
  }
  agent->integrator.advance(t, command);
}

void PlantWorld::publishMeasurement(int index, long k) {
  Follower& follower = followers_[static_cast<std::size_t>(index)];
  Eigen::VectorXd relative = targetOf(follower).state() - follower.agent.state();
  follower.world.addNoise(k, &relative);  // the world's noise of the plant's tick k
  const double t = static_cast<double>(k) / options_.rate;
  switch (channels_->sample(index, k, relative)) {
    case OutageChange::kBegan:
      ROS_WARN_STREAM(name_ << ": " << follower.agent.name << "/relative_measurement outage for "
                            << options_.faults.outage_duration << " s from t = " << t << " s");
      break;
    case OutageChange::kEnded:
      ROS_INFO_STREAM(name_ << ": " << follower.agent.name
                            << "/relative_measurement outage over at t = " << t << " s");
      break;
    case OutageChange::kNone:
      break;
  }
  // Publish what was sampled at least `latency` ago.
  long sampled = 0;
  Eigen::VectorXd measured;
  while (channels_->deliver(index, k, &sampled, &measured)) {
    follower.measurement_publisher.publish(boost::make_shared<RelativeMeasurement>(
        toRelativeMeasurementMsg(measured, clock_->stampOf(sampled), options_.world_frame)));
  }
}

void PlantWorld::advertiseNeighbours(int index) {
  Follower& follower = followers_[static_cast<std::size_t>(index)];
  NeighbourOutput& output = follower.neighbours;
  const std::size_t others = followers_.size();  // the leader and every other follower
  const auto entry = [this](const std::string& id) {
    Neighbour neighbour;
    neighbour.id = id;
    neighbour.position.assign(static_cast<std::size_t>(axes_), 0.0);
    neighbour.velocity.assign(static_cast<std::size_t>(axes_), 0.0);
    return neighbour;
  };
  output.entries.reserve(others);
  output.agents.reserve(others);
  output.entries.push_back(entry(leader_.name));
  output.agents.push_back(0);
  for (std::size_t j = 0; j < followers_.size(); ++j) {
    if (static_cast<int>(j) != index) {
      output.entries.push_back(entry(followers_[j].agent.name));
      output.agents.push_back(static_cast<int>(j) + 1);
    }
  }
  output.taken.assign(others, 0);
  output.message.neighbours.reserve(others);
  output.message.header.frame_id = options_.world_frame;  // relative_measurement's frame
  output.publisher.advertise<NeighbourArray>(nh_, follower.agent.name + "/neighbours", 10);
}

void PlantWorld::publishNeighbours(int index, const ros::Time& stamp) {
  Follower& follower = followers_[static_cast<std::size_t>(index)];
  NeighbourOutput& output = follower.neighbours;
  if (!output.publisher.subscribed()) {
    return;
  }
  // Last tick's entries back to their places (moves: no allocation), then this tick's sensed.
  std::vector<Neighbour>& sensed = output.message.neighbours;
  for (std::size_t e = 0; e < sensed.size(); ++e) {
    output.entries[output.taken[e]] = std::move(sensed[e]);
  }
  sensed.clear();
  const Eigen::VectorXd& own = states_[static_cast<std::size_t>(index) + 1];
  const double radius = scenario_.formation.neighbours.radius;
  for (std::size_t s = 0; s < output.entries.size(); ++s) {
    Neighbour& entry = output.entries[s];
    const Eigen::VectorXd& other = states_[static_cast<std::size_t>(output.agents[s])];
    if (relativeStateWithin(own, other, axes_, radius, &entry.position, &entry.velocity)) {
      output.taken[sensed.size()] = s;
      sensed.push_back(std::move(entry));
    }
  }
  output.message.header.stamp = stamp;
  output.publisher.publish(output.message);  // serialised now: the message stays ours
}

const PlantWorld::Agent& PlantWorld::targetOf(const Follower& follower) const {
  return follower.target == 0 ? leader_
                              : followers_[static_cast<std::size_t>(follower.target - 1)].agent;
}

GenericDimensions::InputVector PlantWorld::commandAt(Agent* agent, const ros::Time& now) {
  const InputGuard& guard = agent->command_timeline.guard();
  const std::int64_t stamp = agent->command_timeline.stamp();
  const bool fresh =
      guard.haveAccepted() &&
      std::abs(1e-9 * static_cast<double>(nanosecondsOf(now) - stamp)) <= options_.command_timeout;
  if (fresh) {
    if (agent->command_timed_out) {
      ROS_INFO_STREAM(name_ << ": " << agent->name << "/command fresh again");
      agent->command_timed_out = false;
    }
    return agent->command;
  }
  if (guard.haveAccepted() && !agent->command_timed_out) {
    ROS_WARN_STREAM(name_ << ": " << agent->name << "/command stamped "
                          << 1e-9 * static_cast<double>(stamp)
                          << " s is older than ~command_timeout (" << options_.command_timeout
                          << " s) at " << now.toSec() << " s: using zero");
    agent->command_timed_out = true;
  }
  return GenericDimensions::InputVector::Zero(axes_);
}

}  // namespace projection_collision_avoidance
