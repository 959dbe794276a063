#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <limits>
#include <memory>
#include <mutex>
#include <string>

#include <nav_msgs/Odometry.h>
#include <ros/ros.h>

#include "projection_collision_avoidance/LeaderBroadcast.h"
#include "projection_collision_avoidance/RelativeMeasurement.h"
#include "projection_collision_avoidance/core/ControllerDesign.hpp"
#include "projection_collision_avoidance/cycle/FollowerCycle.hpp"
#include "projection_collision_avoidance/cycle/InputGuard.hpp"
#include "projection_collision_avoidance/cycle/InputTimeline.hpp"
#include "projection_collision_avoidance/ros/InlineCallbackQueue.hpp"
#include "projection_collision_avoidance/ros/InputAdmission.hpp"
#include "projection_collision_avoidance/vehicle/RelativeStateFromOdometry.hpp"

#include "follower/FollowerOptions.hpp"
#include "follower/MeasurementAdapter.hpp"
#include "follower/NeighbourInput.hpp"

namespace projection_collision_avoidance {

/// What the inputs have refused so far, and the ages of what they accepted, for the status and
/// the diagnostics.
struct FollowerInputStats {
  std::uint64_t rejected_measurements = 0;
  std::uint64_t rejected_leader_broadcasts = 0;
  std::uint64_t rejected_odometry = 0;
  std::uint64_t superseded_odometry = 0;  ///< own odometry older than the latest: dropped
  std::string measurement_rejection;      ///< the latest, "" once one was accepted after it
  std::string leader_rejection;
  /// s, of the last accepted measurement (InputTimeline::age()); +inf: none on this timeline
  double measurement_age = kNoInputAge;
  double leader_age = kNoInputAge;     ///< s, of the last accepted leader broadcast; +inf: none
  std::uint64_t rejected_input = 0;    ///< messages the input adapter refused (~input not
                                       ///< relative_measurement)
  std::uint64_t superseded_input = 0;  ///< the input adapter's messages dropped as superseded
  /// s, the skew of the adapter's latest accepted input (its two stamps apart); NaN: none, as
  /// the other skews
  double input_skew = std::numeric_limits<double>::quiet_NaN();
  /// s, receipt − stamp of the latest accepted measurement / leader broadcast; NaN: none
  double measurement_skew = std::numeric_limits<double>::quiet_NaN();
  double leader_skew = std::numeric_limits<double>::quiet_NaN();
  double clock_offset = 0.0;  ///< s, added to the latest accepted measurement's stamp
  /// Messages of every input refused because another publisher held it (doc/boundary.md)
  std::uint64_t foreign_messages = 0;
  /// ns, receipt time of the latest of them; InputTimeline::kNone before one
  std::int64_t foreign_heard_ns = InputTimeline::kNone;
  /// Times an input's timeline started afresh after refusing everything for its timeout, or
  /// passed to another publisher after its holder went quiet
  std::uint64_t input_restarts = 0;
  std::uint64_t input_handovers = 0;
  /// formation.neighbours: arrays refused, the latest reason, the age of the latest accepted
  std::uint64_t rejected_neighbours = 0;
  std::string neighbour_rejection;
  double neighbours_age = kNoInputAge;
};

/// The follower's inputs: subscribes `relative_measurement` (with ~input relative_measurement;
/// other inputs hand their measurements to admitMeasurement()), `leader_broadcast` and, with a time
/// headway (time_headway > 0), `odom` (nav_msgs/Odometry: its own state; frame ~odom_frame,
/// refused once older than ~measurement_timeout on arrival; read with ~odometry/twist_frame and
/// ~odometry/pose_frame as the odometry input reads it), judges each message with its
/// InputTimeline (doc/boundary.md) on the subscriber's thread, and writes what it accepts into the
/// control cycle's lock-free slots; each accepted measurement is then announced to @p on_accepted
/// (with ~trigger measurement, MeasurementTrigger steps on it). Nothing a message carries can
/// end the node (admitGuarded()). The subscriptions start with start().
class FollowerInputs {
 public:
  /// Told of each measurement written to the cycle, with the control periods skipped between its
  /// stamp and the one accepted before it.
  using AcceptedSink = std::function<void(std::uint32_t skipped)>;

  /// @param design the design at start: its model sizes and leader acceleration (pinv(B) u_d),
  ///        which reconfiguration does not change
  /// @param cycle where accepted inputs go; outlives this object
  /// @param on_accepted told of each accepted measurement (may be empty: nobody is)
  FollowerInputs(std::string node_name, const FollowerNodeOptions& options,
                 const ControllerDesign& design, FollowerCycle* cycle, AcceptedSink on_accepted);

  /// Subscribes the inputs (once what the callbacks use is in place).
  void start(ros::NodeHandle nh);
  /// The own odometry's topic ("" without a time headway), once started.
  std::string odometryTopic() const { return odometry_subscriber_.getTopic(); }
  /// The neighbour arrays' topic ("" without formation.neighbours), once started.
  std::string neighboursTopic() const { return neighbours_ ? neighbours_->topic() : std::string(); }

  /// Judges a relative measurement (from the subscription, or made by an input adapter such as
  /// OdometryInput) and, if accepted, writes it into the cycle (and, with ~trigger measurement,
  /// runs its step). One caller at a time.
  /// @p publisher: the sender's caller id; "" for a measurement made within the node.
  void admitMeasurement(const RelativeMeasurement& msg, std::string_view publisher = {});

  /// The input adapter whose counts stats() reports (nullptr: none); set before start() and
  /// cleared before the adapter goes.
  void setAdapter(const MeasurementAdapter* adapter) {
    adapter_.store(adapter, std::memory_order_release);
  }

  /// Refusal counts, latest reasons and the inputs' ages at ROS time @p now_ns (any thread).
  FollowerInputStats stats(std::int64_t now_ns) const;

  /// The frame the command is expressed in, into @p frame (any thread; no allocation once
  /// @p frame holds a name that long): ~measurement_frame when set, else the frame_id of the
  /// latest accepted measurement (the world frame the input adapter moved it into, or the one
  /// the relative measurement was sent in), else "" (no world frame known).
  void commandFrame(std::string* frame) const;

 private:
  void onMeasurement(const ros::MessageEvent<RelativeMeasurement const>& event);
  void onLeaderBroadcast(const ros::MessageEvent<LeaderBroadcast const>& event);
  void onOdometry(const ros::MessageEvent<nav_msgs::Odometry const>& event);
  std::string name_;
  FollowerNodeOptions options_;
  ControllerDesign design_;  ///< the start's: what the inputs read of it (period, time headway,
                             ///< a_1) does not change by reconfiguration
  int axes_;
  FollowerCycle* cycle_;
  AcceptedSink on_accepted_;

  // Subscriber threads only (one at a time per input: roscpp serialises a subscription), except
  // what each timeline lets other threads read (its age, skew and refusal count).
  InputTimeline measurement_timeline_;
  MeasurementSample measurement_;
  Eigen::VectorXd relative_state_;
  InputTimeline leader_timeline_;
  LeaderSample leader_;
  InputTimeline odometry_timeline_;
  OwnStateSample own_state_;
  Eigen::VectorXd odometry_state_;
  PlanarOrSpatialState origin_state_;  ///< the own odometry's [p; v] before it is accepted
  std::string accepted_frame_;  ///< the latest accepted measurement's frame_id (tfFrameName())

  // Read by other threads.
  std::atomic<const MeasurementAdapter*> adapter_{nullptr};
  std::atomic<double> clock_offset_{0.0};
  mutable std::mutex reasons_mutex_;
  std::string measurement_rejection_;
  std::string leader_rejection_;
  std::string command_frame_;  ///< accepted_frame_, for commandFrame() (reasons_mutex_)

  /// The subscriptions' callbacks run at once on roscpp's network thread (no spinner hand-off).
  InlineCallbackQueue inline_queue_;
  ros::Subscriber measurement_subscriber_;
  ros::Subscriber leader_subscriber_;
  ros::Subscriber odometry_subscriber_;         ///< only with a time headway (S1)
  std::unique_ptr<NeighbourInput> neighbours_;  ///< only with formation.neighbours
};

}  // namespace projection_collision_avoidance
