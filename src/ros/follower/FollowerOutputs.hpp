#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <thread>

#include <diagnostic_updater/diagnostic_updater.h>
#include <ros/ros.h>

#include "projection_collision_avoidance/core/Formation.hpp"
#include "projection_collision_avoidance/cycle/FollowerCycle.hpp"
#include "projection_collision_avoidance/ros/CountedPublisher.hpp"
#include "projection_collision_avoidance/rt/Handoff.hpp"

#include "follower/FollowerInputs.hpp"
#include "follower/FollowerOptions.hpp"

namespace projection_collision_avoidance {

/// The follower's outputs: from each FollowerCycleOutput it publishes `command`
/// (AccelStamped; frame_id the world frame of the measurements, FollowerInputs::commandFrame(),
/// or ~follower_frame when none is known), `broadcast` (its command as a LeaderBroadcast, for a
/// follower behind it), `status` (FollowerStatus) and, every so many steps, `markers`; it updates
/// the diagnostics and writes the log lines the cycle's events call for (mode changes, time jumps,
/// stalls).
///
/// publish() does it on the calling thread (timer loop, measurement trigger; one call at a time).
/// post() is for a
/// real-time thread: it copies the output into a preallocated lock-free queue and rings a
/// doorbell, allocating and blocking on nothing; the outputs' own thread (started by
/// startThread()) publishes from there. A full queue drops the output and counts it (dropped()).
class FollowerOutputs {
 public:
  /// Outputs a real-time thread may get ahead of the publishing thread by.
  static constexpr std::size_t kQueueCapacity = 64;

  /// @param control_rate Hz, for the marker rate
  /// @param inputs the inputs whose refusals and ages the status and diagnostics report
  FollowerOutputs(ros::NodeHandle nh, ros::NodeHandle private_nh, std::string node_name,
                  const FollowerNodeOptions& options, double control_rate,
                  const FormationMember& member, const Eigen::VectorXd& separation,
                  const FollowerInputs* inputs);
  ~FollowerOutputs();
  FollowerOutputs(const FollowerOutputs&) = delete;
  FollowerOutputs& operator=(const FollowerOutputs&) = delete;

  /// Publishes @p out now, on this thread.
  void publish(const FollowerCycleOutput& out);
  /// Queues @p out for the outputs' thread (real-time safe).
  void post(const FollowerCycleOutput& out) { handoff_.post(out); }
  /// Starts the thread that publishes what post() queues; also runs @p idle (for example
  /// collecting retired controllers) at least every 100 ms.
  void startThread(std::function<void()> idle);
  /// Stops and joins that thread (publishing what is queued first).
  void stopThread();
  /// Where the markers go: @p origin gives the frame and the position in it of the follower's
  /// controlled point (false while unknown). Without one: ~follower_frame's origin. Set it
  /// before the first output.
  using MarkerOrigin = std::function<bool(std::string* frame, Eigen::Vector3d* origin)>;
  void setMarkerOrigin(MarkerOrigin origin) { marker_origin_ = std::move(origin); }
  /// The tracker gain G_e in force, for the diagnostics (any thread).
  void describeTrackerGain(const Eigen::MatrixXd& gain);
  /// Outputs dropped because the queue was full (a queue this size never fills at the control
  /// rates of a follower, ~1 kHz at most, unless the publishing thread stands still).
  std::uint64_t dropped() const { return handoff_.dropped(); }

 private:
  void run(const std::function<void()>& idle);
  void logEvents(const FollowerCycleOutput& out);
  void publishMarkers(const FollowerCycleOutput& out);
  void diagnose(diagnostic_updater::DiagnosticStatusWrapper& status);

  std::string name_;
  FollowerNodeOptions options_;
  FormationMember member_;
  Eigen::VectorXd separation_;
  const FollowerInputs* inputs_;
  std::uint64_t steps_per_marker_ = 0;
  std::uint64_t steps_per_status_ = 0;                 ///< 0: no status
  FollowerMode status_mode_ = FollowerMode::kWaiting;  ///< the mode of the latest status
  MarkerOrigin marker_origin_;
  std::string command_frame_;  ///< the command's frame (FollowerInputs::commandFrame()), "": none

  std::mutex publish_mutex_;    ///< publish(): the timer's or outputs' thread vs a measurement's
  FollowerCycleOutput latest_;  ///< the latest step, with the counters of the latest output
  /// Keeps the latest step's results in latest_ and takes the counters and design of @p out.
  void remember(const FollowerCycleOutput& out);
  FollowerMode logged_mode_ = FollowerMode::kWaiting;
  std::mutex gain_mutex_;  ///< tracker_gain_: set by reconfiguration
  std::string tracker_gain_;

  CountedPublisher command_publisher_;
  CountedPublisher broadcast_publisher_;
  CountedPublisher status_publisher_;
  CountedPublisher marker_publisher_;
  diagnostic_updater::Updater diagnostics_;

  Handoff<FollowerCycleOutput, kQueueCapacity> handoff_;
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

}  // namespace projection_collision_avoidance
