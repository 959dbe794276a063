#include "plant/PlantClock.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <sstream>
#include <utility>

namespace projection_collision_avoidance {
namespace {

/// A tick is due when the time is within this fraction of a period of it.
constexpr double kTickTolerance = 1e-6;
/// Wall seconds of ticks that one wall-timer callback may catch up.
constexpr double kMaxCatchUp = 0.05;
/// Steady seconds between two reports of dropped backlog.
constexpr double kDropReportPeriod = 5.0;

}  // namespace

PlantClock::PlantClock(ros::NodeHandle nh, std::string node_name, const PlantNodeOptions& options,
                       std::mutex* mutex, Hooks hooks)
    : name_(std::move(node_name)), options_(options), mutex_(mutex), hooks_(std::move(hooks)) {
  if (options_.duration > 0.0) {
    last_tick_ = std::lround(options_.duration * options_.rate);
  }
  if (options_.publish_clock) {
    // The plant owns simulated time: it must not wait on ROS time (which stays 0 under
    // use_sim_time until a /clock arrives), so it ticks on wall time.
    started_ = true;
    origin_ = ros::Time(0);
    wall_origin_ = ros::WallTime::now();
    rate_check_wall_ = wall_origin_;
    waiting_for_followers_ = options_.wait_for_followers > 0.0;
    wall_timer_ =
        nh.createWallTimer(ros::WallDuration(1.0 / (options_.rate * options_.real_time_factor)),
                           &PlantClock::onWallTick, this);
  } else if (!ticksOnThread(options_)) {
    timer_ = nh.createTimer(ros::Duration(1.0 / options_.rate), &PlantClock::onRosTick, this);
  } else {
    // Half a period off the followers' shared ticks at the same rate (on the grid k * period):
    // in one process the plant's tick and their round do not contend for roscpp's locks.
    const std::chrono::nanoseconds period(std::llround(1e9 / options_.rate));
    thread_.start(
        period, 0, [this](const PeriodicTick& tick) { onThreadTick(tick); }, "plant tick",
        period / 2);
  }
}

PlantClock::~PlantClock() { thread_.stop(); }

bool PlantClock::ticksOnThread(const PlantNodeOptions& options) {
  return !options.publish_clock && !ros::Time::isSimTime();
}

void PlantClock::onThreadTick(const PeriodicTick& tick) {
  if (!ros::ok()) {  // shutting down: a timer's callback would not run either
    return;
  }
  if (hooks_.before_tick) {
    {
      // After a stall plant time moves up to the wall clock first: the commands queued meanwhile
      // are stamped on it, and would be judged ahead of the stalled plant time.
      const std::lock_guard<std::mutex> lock(*mutex_);
      dropWallBacklogNow();
    }
    hooks_.before_tick();
  }
  const std::lock_guard<std::mutex> lock(*mutex_);
  try {
    // When the tick was due, on ROS (wall) time: now less how late the thread woke.
    ros::Time expected;
    expected.fromNSec(nanosecondsOf(ros::Time::now()) - (tick.actual - tick.expected));
    rosTick(expected);
  } catch (const std::exception& error) {
    ROS_ERROR_STREAM_THROTTLE(5.0, name_ << ": tick failed: " << error.what());
  }
}

ros::Time PlantClock::stampOf(long k) const {
  const double offset_ns = static_cast<double>(k) * 1e9 / options_.rate;
  ros::Time stamp;
  stamp.fromNSec(origin_.toNSec() + static_cast<uint64_t>(std::llround(offset_ns)));
  return stamp;
}

ros::Time PlantClock::now() const {
  return started_ ? stampOf(std::max(0L, next_tick_ - 1)) : ros::Time::now();
}

void PlantClock::halt() {
  running_ = false;
  wall_timer_.stop();
  timer_.stop();
}

void PlantClock::runThrough(long due, const ros::WallTime& wall_now) {
  while (running_ && next_tick_ <= due) {
    if (options_.lockstep && holdForCommands(wall_now)) {
      break;
    }
    running_ = hooks_.tick(next_tick_);
    ++next_tick_;
  }
}

bool PlantClock::waitingForFollowers(const ros::WallTime& now) {
  if (!waiting_for_followers_) {
    return false;
  }
  // Simulated time starts once every follower listens and every topic waited for has a
  // subscriber, or ~wait_for_followers s after start.
  const std::pair<int, int> listening = hooks_.listening();
  const double waited = (now - wall_origin_).toSec();
  const bool all = listening.first == listening.second;
  if (!all && waited < options_.wait_for_followers) {
    return true;
  }
  waiting_for_followers_ = false;
  if (all) {
    ROS_INFO_STREAM(name_ << ": every follower listens (and every topic of "
                             "~wait_for_subscribers has a subscriber) after "
                          << waited << " s: simulated time starts");
  } else {
    ROS_WARN_STREAM(name_ << ": " << listening.first << " of " << listening.second
                          << " followers listening and topics of ~wait_for_subscribers "
                             "subscribed after ~wait_for_followers = "
                          << waited << " s: simulated time starts without the others");
  }
  wall_origin_ = now;
  rate_check_wall_ = now;
  return false;
}

bool PlantClock::holdForCommands(const ros::WallTime& now) {
  if (next_tick_ == 0 || hooks_.answered(next_tick_ - 1)) {
    holding_ = false;
    return false;
  }
  if (!holding_) {
    holding_ = true;
    hold_start_ = now;
  }
  if ((now - hold_start_).toSec() < options_.lockstep_timeout) {
    // Simulated time waits: the wall schedule restarts from here.
    wall_origin_ = now - ros::WallDuration(static_cast<double>(next_tick_) / wallRate(now));
    return true;
  }
  holding_ = false;
  ++lockstep_timeouts_;
  ROS_WARN_STREAM_THROTTLE(5.0, name_ << ": lockstep: tick " << next_tick_ << " waited "
                                      << options_.lockstep_timeout
                                      << " s for the commands and runs without them ("
                                      << lockstep_timeouts_ << " such ticks)");
  return false;
}

double PlantClock::wallRate(const ros::WallTime& now) {
  const double factor = options_.lockstep && !hooks_.all_commanded()
                            ? std::min(1.0, options_.real_time_factor)
                            : options_.real_time_factor;
  if (factor != factor_) {
    // The schedule goes on from the tick due now, at the new pace.
    if (factor_ > 0.0) {
      wall_origin_ =
          now - ros::WallDuration(static_cast<double>(next_tick_) / (options_.rate * factor));
    }
    factor_ = factor;
  }
  return options_.rate * factor_;
}

void PlantClock::onWallTick(const ros::WallTimerEvent& /*event*/) {
  const std::lock_guard<std::mutex> lock(*mutex_);
  if (!running_) {
    return;
  }
  // Tick k is due at wall time wall_origin_ + k / (rate * real_time_factor). A callback that
  // runs late catches up the ticks due since (at most kMaxCatchUp s of them at once), so that
  // simulated time keeps the real-time factor on average; a backlog beyond that is dropped
  // (simulated time slows down) and reported below.
  const ros::WallTime now = ros::WallTime::now();
  if (waitingForFollowers(now)) {
    return;
  }
  const double wall_rate = wallRate(now);
  long due =
      static_cast<long>(std::floor((now - wall_origin_).toSec() * wall_rate + kTickTolerance));
  const long max_catch_up = std::max(1L, std::lround(kMaxCatchUp * wall_rate));
  if (due - next_tick_ >= max_catch_up) {
    due = next_tick_;
    wall_origin_ = now - ros::WallDuration(static_cast<double>(next_tick_) / wall_rate);
  }
  runThrough(due, now);
  // Report, at most every 5 s, a simulation slower than the real-time factor asked for.
  const double wall = (now - rate_check_wall_).toSec();
  if (wall >= 5.0) {
    const double factor = static_cast<double>(next_tick_ - rate_check_tick_) / options_.rate / wall;
    if (factor < 0.9 * factor_) {
      ROS_WARN_STREAM(name_ << ": simulating at " << factor << "x real time, below the " << factor_
                            << "x asked for");
    }
    rate_check_wall_ = now;
    rate_check_tick_ = next_tick_;
  }
}

void PlantClock::onRosTick(const ros::TimerEvent& event) {
  const std::lock_guard<std::mutex> lock(*mutex_);
  try {
    rosTick(event.current_expected);
  } catch (const std::exception& error) {
    ROS_ERROR_STREAM_THROTTLE(5.0, name_ << ": tick failed: " << error.what());
  }
}

void PlantClock::rosTick(const ros::Time& expected) {
  const ros::Time now = ros::Time::now();
  if (!running_ || now.isZero()) {
    return;
  }
  if (wentBack(clock_, now)) {
    ROS_WARN_STREAM(name_ << ": ROS time went back by " << -clock_.jump() << " s, to "
                          << now.toSec() << " s; waiting for it to reach "
                          << stampOf(next_tick_).toSec() << " s again");
    hooks_.jump(clock_.jump());
  }
  if (!started_) {
    // Under use_sim_time scenario time is ROS time; otherwise it starts at the first tick.
    started_ = true;
    // On wall time the ticks are counted from when the timer was due, not from when its first
    // callback ran: the later callbacks, each a little after its own due time, then never floor
    // to the tick before (which would publish every sample a period late).
    origin_ = ros::Time::isSimTime()                    ? ros::Time(0)
              : (!expected.isZero() && expected <= now) ? expected
                                                        : now;
    next_tick_ = ros::Time::isSimTime()
                     ? static_cast<long>(
                           std::ceil(secondsBetween(now, origin_) * options_.rate - kTickTolerance))
                     : 0;
    if (last_tick_ >= 0 && next_tick_ > last_tick_) {
      std::ostringstream why;
      why << "ROS time " << now.toSec() << " s is already past ~duration = " << options_.duration
          << " s";
      hooks_.stop(why.str());
      return;
    }
  }
  long due = dueAt(now);
  if (due < next_tick_ - 1) {
    return;  // ROS time went back: wait for it to reach the next tick again
  }
  if (!ros::Time::isSimTime()) {
    due = dropWallBacklog(due, now);
  }
  // Catch up every due tick, at most one second of them per call.
  runThrough(std::min(due, next_tick_ + std::max(1L, std::lround(options_.rate))),
             ros::WallTime::now());
}

void PlantClock::dropWallBacklogNow() {
  const ros::Time now = ros::Time::now();
  if (!started_ || !running_ || now.isZero()) {
    return;
  }
  dropWallBacklog(dueAt(now), now);
}

long PlantClock::dueAt(const ros::Time& now) const {
  return static_cast<long>(
      std::floor(secondsBetween(now, origin_) * options_.rate + kTickTolerance));
}

long PlantClock::dropWallBacklog(long due, const ros::Time& now) {
  const long max_catch_up = std::max(1L, std::lround(kMaxCatchUp * options_.rate));
  if (due - next_tick_ >= max_catch_up) {
    // The ticks from next_tick_ on are stamped from now: no stamp lags the wall clock by more
    // than kMaxCatchUp, so neither the samples nor the judgement of the commands (stamped by
    // their senders on the wall clock) fall behind; scenario time runs slower instead.
    const double behind = static_cast<double>(due - next_tick_ + 1) / options_.rate;
    dropped_seconds_ += behind;
    unreported_seconds_ += behind;
    origin_ = now - ros::Duration(static_cast<double>(next_tick_) / options_.rate);
    due = next_tick_;
  }
  reportDrops();
  return due;
}

void PlantClock::reportDrops() {
  if (unreported_seconds_ <= 0.0) {
    return;
  }
  // At most one report per kDropReportPeriod, and none withheld for longer: what a period
  // holds back (a stall just after a small drop was reported) is reported when it ends.
  const ros::SteadyTime now = ros::SteadyTime::now();
  if (!last_drop_report_.isZero() && (now - last_drop_report_).toSec() < kDropReportPeriod) {
    return;
  }
  ROS_WARN_STREAM(name_ << ": " << unreported_seconds_
                        << " s behind the wall clock since the last report (the plant was "
                           "stalled or cannot keep up with ~rate): those ticks are dropped, "
                           "scenario time runs slower than wall time ("
                        << dropped_seconds_ << " s dropped in all)");
  unreported_seconds_ = 0.0;
  last_drop_report_ = now;
}

}  // namespace projection_collision_avoidance
