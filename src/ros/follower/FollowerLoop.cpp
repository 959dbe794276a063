#include "follower/FollowerLoop.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <string>
#include <utility>

#include "projection_collision_avoidance/core/ParameterError.hpp"
#include "projection_collision_avoidance/ros/InputAdmission.hpp"

namespace projection_collision_avoidance {
namespace {

/// ROS time now (ns); a tick reads it once it has latched its inputs.
std::int64_t rosNanoseconds() { return nanosecondsOf(ros::Time::now()); }

/// CLOCK_MONOTONIC (ns), the clock of the real-time thread's ticks.
std::int64_t steadyNanoseconds() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

}  // namespace

FollowerLoop::FollowerLoop(ros::NodeHandle nh, std::string node_name,
                           const std::string& thread_name, const FollowerNodeOptions& options,
                           double control_rate, FollowerCycle* cycle, FollowerOutputs* outputs)
    : name_(std::move(node_name)),
      count_timer_periods_(options.trigger == ControlTrigger::kTimer),
      post_outputs_(options.control_loop == ControlLoop::kThread),
      cycle_(cycle),
      outputs_(outputs),
      period_(1.0 / control_rate) {
  const auto period = std::chrono::nanoseconds(std::llround(1e9 / control_rate));
  if (options.control_loop == ControlLoop::kTimer && !ros::Time::isSimTime()) {
    shared_ = std::make_unique<SharedTicker>(
        period, "follower ticks", [this](const PeriodicTick& tick) { onThreadTick(tick); });
    return;
  }
  if (options.control_loop == ControlLoop::kThread) {
    const int priority = options.control_priority;
    try {
      thread_.start(
          period, priority, [this](const PeriodicTick& tick) { onThreadTick(tick); }, thread_name);
    } catch (const PriorityRefused& error) {
      throw ParameterError("~control_priority",
                           "SCHED_FIFO priority " + std::to_string(priority) +
                               " refused: pthread_setschedparam failed: " + error.code().message() +
                               " (needs root or CAP_SYS_NICE, or an RLIMIT_RTPRIO of at least " +
                               std::to_string(priority) + "; 0 runs without real-time priority)");
    }
    return;
  }
  ros::TimerOptions timer_options(
      ros::Duration(period_), [this](const ros::TimerEvent& event) { onTimer(event); }, &queue_);
  timer_ = nh.createTimer(timer_options);
  spinner_ = std::make_unique<ros::AsyncSpinner>(1, &queue_);
  spinner_->start();
}

FollowerLoop::~FollowerLoop() {
  thread_.stop();
  shared_.reset();  // after a running round of the shared ticks
  timer_.stop();
  if (spinner_) {
    spinner_->stop();
  }
}

void FollowerLoop::onTimer(const ros::TimerEvent& event) {
  try {
    const ros::Time now = ros::Time::now();
    if (wentBack(clock_, now)) {
      have_last_expected_ = false;  // the expected times of the old timeline do not count
    }
    const double delay = secondsBetween(event.current_real, event.current_expected);
    std::uint32_t skipped = 0;
    if (count_timer_periods_) {
      if (have_last_expected_) {
        skipped = skippedPeriods(secondsBetween(event.current_expected, last_expected_), period_);
      }
      last_expected_ = event.current_expected;
      have_last_expected_ = true;
    }
    cycle_->tick(rosNanoseconds, steadyNanoseconds(), delay, skipped, &timer_output_);
    outputs_->publish(timer_output_);
  } catch (const std::exception& error) {
    ROS_ERROR_STREAM_THROTTLE(5.0, name_ << ": control tick failed: " << error.what());
  }
}

void FollowerLoop::onThreadTick(const PeriodicTick& tick) {
  if (!ros::ok()) {  // shutting down: the timer's spinner would not call it either
    return;
  }
  try {
    cycle_->tickOn(tick, rosNanoseconds, &thread_output_);
    if (post_outputs_) {
      outputs_->post(thread_output_);
    } else {
      outputs_->publish(thread_output_);
    }
  } catch (const std::exception& error) {
    ROS_ERROR_STREAM_THROTTLE(5.0, name_ << ": control tick failed: " << error.what());
  }
}

}  // namespace projection_collision_avoidance
