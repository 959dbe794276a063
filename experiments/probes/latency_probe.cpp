/// Latency probe of the follower pipeline (experiments/probes/latency.launch,
/// experiments/ros_latency/run.sh).
///
/// Publishes RelativeMeasurement on `relative_measurement` at ~rate Hz from a thread of its own
/// (clock_nanosleep(TIMER_ABSTIME) on CLOCK_MONOTONIC; a wake-up more than a period late skips
/// the periods it missed rather than bursting), each stamped with ros::Time::now() (real time)
/// taken immediately before publish(), frame ~frame_id, a constant relative state (~position,
/// ~velocity on one axis). After ~warmup s (not counted) it measures for ~duration s, then waits
/// ~drain s for the last answers. It subscribes (TCP_NODELAY) to
///   relay_output        the bare relay's output (measurement_relay)
///   measurement_command the measurement-triggered follower's command: latency = receipt time -
///                       header.stamp (the stamp of the measurement it answers)
///   measurement_status  its status (ticks, missed and late periods, tick_delay)
///   timer_command       the timer-triggered follower's command, paired by header.stamp with
///   timer_status        its status: latency = command receipt time - (status.header.stamp -
///                       status.measurement_age), the stamp of the measurement the tick used,
///                       for every command of a tick in the window; "first_answers": only the
///                       first command that used each measurement (a measurement no tick used
///                       has none)
/// The receipt time is the one roscpp takes when the message has been read off the socket
/// (ros::MessageEvent::getReceiptTime()), so that the probe's own callback queue does not count;
/// the time at the callback is reported too ("callback_latency_us").
///
/// publish() writes to the subscribers of relative_measurement one after the other, in the order
/// they connected ("send_order" in the JSON), so the later ones get their copy a little later.
///
/// Only measurements published in the measured window count (by their stamps). Writes ~output
/// (JSON): per stream published/received counts and latency p50/p90/p99/max in microseconds; per
/// follower ticks, missed_periods and late_periods within the window (the status at the window's
/// end minus the one before it) and their percentage of the expected periods (duration * rate),
/// tick_delay p50/p99, and the totals of its final status. Then ros::shutdown() and exit 0, or 1
/// when something never arrived (2: bad parameters or simulated time).

#include <algorithm>
#include <atomic>
#include <cinttypes>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include <geometry_msgs/AccelStamped.h>
#include <ros/ros.h>
#include <time.h>

#include "projection_collision_avoidance/FollowerStatus.h"
#include "projection_collision_avoidance/RelativeMeasurement.h"

namespace {

using projection_collision_avoidance::FollowerStatus;
using projection_collision_avoidance::RelativeMeasurement;

constexpr std::int64_t kNsPerS = 1000000000;

/// One message of a latency stream: the stamp it answers, when it was read off the socket and
/// when its callback ran (ns of ROS time).
struct Arrival {
  std::int64_t stamp;
  std::int64_t receipt;
  std::int64_t callback;
};

/// What the probe keeps of one status.
struct StatusSample {
  std::int64_t stamp;              ///< the tick
  std::int64_t measurement_stamp;  ///< stamp - measurement_age: the measurement the tick used
  double tick_delay;               ///< s
  std::uint64_t ticks;
  std::uint32_t missed_periods;
  std::uint32_t late_periods;
};

/// Appends to a vector preallocated at start, without ever growing it (a full one counts drops).
template <typename T>
class Recorder {
 public:
  explicit Recorder(std::size_t capacity) { samples_.reserve(capacity); }
  void add(const T& sample) {
    const std::lock_guard<std::mutex> lock(mutex_);
    if (samples_.size() < samples_.capacity()) {
      samples_.push_back(sample);
    } else {
      ++overflow_;
    }
  }
  /// After the spinner stopped.
  const std::vector<T>& samples() const { return samples_; }
  std::size_t overflow() const { return overflow_; }

 private:
  std::mutex mutex_;
  std::vector<T> samples_;
  std::size_t overflow_ = 0;
};

/// Nearest-rank percentiles of a sample, in the unit of the sample.
struct Percentiles {
  std::size_t count = 0;
  double p50 = NAN, p90 = NAN, p99 = NAN, max = NAN;
};

Percentiles percentiles(std::vector<double> values) {
  Percentiles p;
  p.count = values.size();
  if (values.empty()) {
    return p;
  }
  std::sort(values.begin(), values.end());
  const auto rank = [&values](double q) {
    const auto index = static_cast<std::size_t>(std::ceil(q * static_cast<double>(values.size())));
    return values[std::min(values.size() - 1, index == 0 ? 0 : index - 1)];
  };
  p.p50 = rank(0.50);
  p.p90 = rank(0.90);
  p.p99 = rank(0.99);
  p.max = values.back();
  return p;
}

std::string number(double value) {
  if (!std::isfinite(value)) {
    return "null";
  }
  char text[64];
  std::snprintf(text, sizeof(text), "%.3f", value);
  return text;
}

std::string json(const Percentiles& p) {
  return "{\"count\": " + std::to_string(p.count) + ", \"p50\": " + number(p.p50) +
         ", \"p90\": " + number(p.p90) + ", \"p99\": " + number(p.p99) +
         ", \"max\": " + number(p.max) + "}";
}

std::int64_t nanoseconds(const ros::Time& time) { return static_cast<std::int64_t>(time.toNSec()); }

std::int64_t monotonicNs() {
  timespec now{};
  clock_gettime(CLOCK_MONOTONIC, &now);
  return static_cast<std::int64_t>(now.tv_sec) * kNsPerS + now.tv_nsec;
}

class LatencyProbe {
 public:
  LatencyProbe(ros::NodeHandle nh, ros::NodeHandle private_nh) : nh_(nh) {
    private_nh.param("rate", rate_, 1000.0);
    private_nh.param("duration", duration_, 60.0);
    private_nh.param("warmup", warmup_, 3.0);
    private_nh.param("drain", drain_, 1.0);
    private_nh.param("connect_timeout", connect_timeout_, 60.0);
    private_nh.param("min_subscribers", min_subscribers_, 3);
    private_nh.param("frame_id", frame_id_, std::string("world"));
    private_nh.param("position", position_, 5.5);
    private_nh.param("velocity", velocity_, 0.1);
    private_nh.param("output", output_, std::string("latency.json"));
    valid_ = rate_ > 0.0 && rate_ <= 100000.0 && duration_ > 0.0 && warmup_ >= 0.0 &&
             drain_ >= 0.0 && connect_timeout_ > 0.0 && !output_.empty();
    const auto capacity =
        static_cast<std::size_t>((warmup_ + duration_ + drain_ + 5.0) * rate_ * 1.5);
    if (!valid_) {
      return;
    }
    publish_delays_.reserve(capacity);
    relay_ = std::make_unique<Recorder<Arrival>>(capacity);
    measurement_command_ = std::make_unique<Recorder<Arrival>>(capacity);
    timer_command_ = std::make_unique<Recorder<Arrival>>(capacity);
    measurement_status_ = std::make_unique<Recorder<StatusSample>>(capacity);
    timer_status_ = std::make_unique<Recorder<StatusSample>>(capacity);

    const ros::TransportHints hints = ros::TransportHints().tcpNoDelay();
    const uint32_t queue = 1000;
    publisher_ = nh_.advertise<RelativeMeasurement>(
        "relative_measurement", 10, [this](const ros::SingleSubscriberPublisher& subscriber) {
          const std::lock_guard<std::mutex> lock(order_mutex_);
          send_order_.push_back(subscriber.getSubscriberName());
        });
    subscribers_.push_back(
        nh_.subscribe("relay_output", queue, &LatencyProbe::onRelay, this, hints));
    subscribers_.push_back(nh_.subscribe("measurement_command", queue,
                                         &LatencyProbe::onMeasurementCommand, this, hints));
    subscribers_.push_back(
        nh_.subscribe("timer_command", queue, &LatencyProbe::onTimerCommand, this, hints));
    subscribers_.push_back(nh_.subscribe("measurement_status", queue,
                                         &LatencyProbe::onMeasurementStatus, this, hints));
    subscribers_.push_back(
        nh_.subscribe("timer_status", queue, &LatencyProbe::onTimerStatus, this, hints));
  }

  int run() {
    if (!valid_) {
      ROS_FATAL(
          "latency_probe: invalid parameters (rate in (0, 1e5], duration > 0, warmup >= 0, "
          "drain >= 0, connect_timeout > 0, output not empty)");
      return 2;
    }
    if (ros::Time::isSimTime()) {
      ROS_FATAL("latency_probe: needs real time (/use_sim_time is true)");
      return 2;
    }
    ros::AsyncSpinner spinner(1);
    spinner.start();
    if (!waitForConnections()) {
      return 1;
    }
    ROS_INFO("latency_probe: connected; %.0f Hz, %.1f s warm-up, %.1f s measured", rate_, warmup_,
             duration_);
    std::thread publisher([this] { publish(); });
    publisher.join();
    // The answers to the last measurements (wall time; ROS time is real time here anyway).
    ros::WallDuration(drain_).sleep();
    spinner.stop();
    for (ros::Subscriber& subscriber : subscribers_) {
      subscriber.shutdown();
    }
    return report();
  }

 private:
  bool waitForConnections() {
    const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(connect_timeout_);
    while (ros::ok() && ros::WallTime::now() < deadline) {
      bool connected = static_cast<int>(publisher_.getNumSubscribers()) >= min_subscribers_;
      for (const ros::Subscriber& subscriber : subscribers_) {
        connected = connected && subscriber.getNumPublishers() > 0;
      }
      if (connected) {
        return true;
      }
      ros::WallDuration(0.05).sleep();
    }
    std::string missing;
    if (static_cast<int>(publisher_.getNumSubscribers()) < min_subscribers_) {
      missing += " relative_measurement has " + std::to_string(publisher_.getNumSubscribers()) +
                 " of " + std::to_string(min_subscribers_) + " subscribers;";
    }
    for (const ros::Subscriber& subscriber : subscribers_) {
      if (subscriber.getNumPublishers() == 0) {
        missing += " no publisher on " + subscriber.getTopic() + ";";
      }
    }
    ROS_FATAL_STREAM("latency_probe: not connected after " << connect_timeout_ << " s:" << missing);
    return false;
  }

  /// The publishing thread: one measurement per period on an absolute monotonic schedule.
  void publish() {
    const auto period = static_cast<std::int64_t>(std::llround(1e9 / rate_));
    const auto warmup_periods = static_cast<std::int64_t>(std::llround(warmup_ * rate_));
    const auto total_periods =
        warmup_periods + static_cast<std::int64_t>(std::llround(duration_ * rate_));
    RelativeMeasurement msg;
    msg.header.frame_id = frame_id_;
    msg.position = {position_};
    msg.velocity = {velocity_};
    const std::int64_t start = monotonicNs() + 10 * 1000 * 1000;
    for (std::int64_t k = 0; k < total_periods && ros::ok();) {
      std::int64_t due = start + k * period;
      timespec wake{};
      wake.tv_sec = static_cast<time_t>(due / kNsPerS);
      wake.tv_nsec = static_cast<long>(due % kNsPerS);
      while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &wake, nullptr) != 0) {
      }
      std::int64_t late = monotonicNs() - due;
      if (late >= period) {  // skip the periods slept through rather than bursting
        const std::int64_t skip = late / period;
        // Periods k .. k + skip - 1 are skipped; count those of the measured window.
        const std::int64_t first = std::max(k, warmup_periods);
        const std::int64_t end = std::min(k + skip, total_periods);
        skipped_ += static_cast<std::uint64_t>(std::max<std::int64_t>(0, end - first));
        k += skip;
        if (k >= total_periods) {
          break;
        }
        due += skip * period;
        late -= skip * period;
      }
      const bool measured = k >= warmup_periods;
      msg.header.seq = static_cast<std::uint32_t>(k);
      msg.header.stamp = ros::Time::now();
      publisher_.publish(msg);
      if (measured) {
        if (published_ == 0) {
          window_start_ = nanoseconds(msg.header.stamp);
        }
        window_end_ = nanoseconds(msg.header.stamp);
        ++published_;
        if (publish_delays_.size() < publish_delays_.capacity()) {
          publish_delays_.push_back(static_cast<double>(late) * 1e-3);
        }
      }
      ++k;
    }
  }

  static Arrival arrival(const ros::Time& stamp, const ros::Time& receipt) {
    return Arrival{nanoseconds(stamp), nanoseconds(receipt), nanoseconds(ros::Time::now())};
  }

  static StatusSample sample(const FollowerStatus& msg) {
    const std::int64_t stamp = nanoseconds(msg.header.stamp);
    return StatusSample{stamp,
                        stamp - std::llround(msg.measurement_age * 1e9),
                        msg.tick_delay,
                        msg.ticks,
                        msg.missed_periods,
                        msg.late_periods};
  }

  void onRelay(const ros::MessageEvent<RelativeMeasurement const>& event) {
    relay_->add(arrival(event.getMessage()->header.stamp, event.getReceiptTime()));
  }
  void onMeasurementCommand(const ros::MessageEvent<geometry_msgs::AccelStamped const>& event) {
    measurement_command_->add(arrival(event.getMessage()->header.stamp, event.getReceiptTime()));
  }
  void onTimerCommand(const ros::MessageEvent<geometry_msgs::AccelStamped const>& event) {
    timer_command_->add(arrival(event.getMessage()->header.stamp, event.getReceiptTime()));
  }
  void onMeasurementStatus(const FollowerStatus::ConstPtr& msg) {
    measurement_status_->add(sample(*msg));
  }
  void onTimerStatus(const FollowerStatus::ConstPtr& msg) { timer_status_->add(sample(*msg)); }

  bool inWindow(std::int64_t stamp) const { return stamp >= window_start_ && stamp <= window_end_; }

  /// Latency figures of arrivals whose answered stamp lies in the window.
  std::string stream(const std::vector<Arrival>& arrivals, std::size_t* received) const {
    std::vector<double> latency;
    std::vector<double> callback;
    latency.reserve(arrivals.size());
    callback.reserve(arrivals.size());
    for (const Arrival& a : arrivals) {
      if (inWindow(a.stamp)) {
        latency.push_back(static_cast<double>(a.receipt - a.stamp) * 1e-3);
        callback.push_back(static_cast<double>(a.callback - a.stamp) * 1e-3);
      }
    }
    *received = latency.size();
    return "{\"published\": " + std::to_string(published_) +
           ", \"received\": " + std::to_string(latency.size()) +
           ", \"latency_us\": " + json(percentiles(latency)) +
           ", \"callback_latency_us\": " + json(percentiles(callback)) + "}";
  }

  /// The timer follower's commands of the ticks in the window with the measurement stamps of
  /// their statuses (same header.stamp): arrivals stamped with the measurement each tick used.
  /// With @p first_only, only the first command that used each measurement.
  std::vector<Arrival> pairTimer(bool first_only) const {
    std::vector<Arrival> commands = timer_command_->samples();
    std::vector<StatusSample> statuses = timer_status_->samples();
    const auto by_stamp = [](const auto& a, const auto& b) { return a.stamp < b.stamp; };
    std::stable_sort(commands.begin(), commands.end(), by_stamp);
    std::stable_sort(statuses.begin(), statuses.end(), by_stamp);
    std::vector<Arrival> paired;
    paired.reserve(commands.size());
    std::size_t j = 0;
    std::int64_t last_measurement = -1;
    for (const Arrival& c : commands) {
      while (j < statuses.size() && statuses[j].stamp < c.stamp) {
        ++j;
      }
      if (!inWindow(c.stamp) || j == statuses.size() || statuses[j].stamp != c.stamp) {
        continue;
      }
      const std::int64_t measurement = statuses[j].measurement_stamp;
      if (first_only && measurement == last_measurement) {
        continue;
      }
      last_measurement = measurement;
      paired.push_back(Arrival{measurement, c.receipt, c.callback});
    }
    return paired;
  }

  /// Period accounting of one follower over the window, from its statuses (by tick stamp).
  std::string follower(const std::vector<StatusSample>& statuses, bool* heard) const {
    const StatusSample* before = nullptr;  // the last status before the window
    const StatusSample* last = nullptr;    // the last status in it
    std::vector<double> delays;
    delays.reserve(statuses.size());
    for (const StatusSample& s : statuses) {
      if (s.stamp < window_start_) {
        before = &s;
      } else if (s.stamp <= window_end_) {
        last = &s;
        delays.push_back(s.tick_delay * 1e6);
      }
    }
    *heard = last != nullptr;
    const double expected = duration_ * rate_;
    const StatusSample zero{0, 0, 0.0, 0, 0, 0};
    const StatusSample& a = before != nullptr ? *before : zero;
    const StatusSample& b = last != nullptr ? *last : zero;
    const double ticks = static_cast<double>(b.ticks - a.ticks);
    const double missed = static_cast<double>(b.missed_periods - a.missed_periods);
    const double late = static_cast<double>(b.late_periods - a.late_periods);
    const Percentiles d = percentiles(delays);
    const StatusSample& final_status = statuses.empty() ? zero : statuses.back();
    return "{\"statuses\": " + std::to_string(delays.size()) +
           ", \"baseline_before_window\": " + (before != nullptr ? "true" : "false") +
           ", \"ticks\": " + number(ticks) + ", \"missed_periods\": " + number(missed) +
           ", \"late_periods\": " + number(late) +
           ", \"ticks_percent\": " + number(100.0 * ticks / expected) +
           ", \"missed_percent\": " + number(100.0 * missed / expected) +
           ", \"late_percent\": " + number(100.0 * late / expected) +
           ", \"tick_delay_us\": {\"p50\": " + number(d.p50) + ", \"p99\": " + number(d.p99) +
           ", \"max\": " + number(d.max) + "}" +
           ", \"final_status\": {\"ticks\": " + std::to_string(final_status.ticks) +
           ", \"missed_periods\": " + std::to_string(final_status.missed_periods) +
           ", \"late_periods\": " + std::to_string(final_status.late_periods) + "}}";
  }

  std::string sendOrder() {
    const std::lock_guard<std::mutex> lock(order_mutex_);
    std::string text = "[";
    for (const std::string& name : send_order_) {
      text += (text.size() > 1 ? ", \"" : "\"") + name + "\"";
    }
    return text + "]";
  }

  int report() {
    std::size_t relay_received = 0;
    std::size_t measurement_received = 0;
    std::size_t timer_received = 0;
    bool measurement_heard = false;
    bool timer_heard = false;
    const std::string relay = stream(relay_->samples(), &relay_received);
    const std::string measurement = stream(measurement_command_->samples(), &measurement_received);
    std::string timer = stream(pairTimer(false), &timer_received);
    std::size_t answered = 0;
    const std::string first_answers = stream(pairTimer(true), &answered);
    // Per measurement rather than per command: the first command that used each one.
    timer.pop_back();
    timer += ", \"first_answers\": " + first_answers + "}";
    const std::string measurement_follower =
        follower(measurement_status_->samples(), &measurement_heard);
    const std::string timer_follower = follower(timer_status_->samples(), &timer_heard);
    const Percentiles delay = percentiles(publish_delays_);
    const std::size_t overflow = relay_->overflow() + measurement_command_->overflow() +
                                 timer_command_->overflow() + measurement_status_->overflow() +
                                 timer_status_->overflow();
    const std::string text =
        "{\n  \"rate_hz\": " + number(rate_) + ",\n  \"duration_s\": " + number(duration_) +
        ",\n  \"warmup_s\": " + number(warmup_) +
        ",\n  \"expected_periods\": " + number(duration_ * rate_) +
        ",\n  \"window_s\": " + number(static_cast<double>(window_end_ - window_start_) * 1e-9) +
        ",\n  \"probe\": {\"published\": " + std::to_string(published_) +
        ", \"skipped_periods\": " + std::to_string(skipped_) +
        ", \"publish_delay_us\": " + json(delay) +
        ", \"recorder_overflow\": " + std::to_string(overflow) +
        ", \"send_order\": " + sendOrder() + "}" + ",\n  \"streams\": {\n    \"relay\": " + relay +
        ",\n    \"follower_measurement\": " + measurement + ",\n    \"follower_timer\": " + timer +
        "\n  },\n  \"followers\": {\n    \"follower_measurement\": " + measurement_follower +
        ",\n    \"follower_timer\": " + timer_follower + "\n  }\n}\n";
    std::FILE* file = std::fopen(output_.c_str(), "w");
    if (file == nullptr || std::fputs(text.c_str(), file) < 0 || std::fclose(file) != 0) {
      ROS_FATAL_STREAM("latency_probe: cannot write " << output_);
      return 1;
    }
    ROS_INFO_STREAM("latency_probe: wrote " << output_ << "\n" << text);
    std::string missing;
    const auto need = [&missing](bool ok, const char* what) {
      if (!ok) {
        missing += std::string(" ") + what;
      }
    };
    need(published_ > 0, "published measurements");
    need(relay_received > 0, "relay output");
    need(measurement_received > 0, "measurement-triggered commands");
    need(timer_received > 0, "timer-triggered commands paired with statuses");
    need(measurement_heard, "measurement-triggered status");
    need(timer_heard, "timer-triggered status");
    if (!missing.empty()) {
      ROS_FATAL_STREAM("latency_probe: nothing in the window from:" << missing);
      return 1;
    }
    return 0;
  }

  ros::NodeHandle nh_;
  bool valid_ = false;
  double rate_ = 1000.0;
  double duration_ = 60.0;
  double warmup_ = 3.0;
  double drain_ = 1.0;
  double connect_timeout_ = 60.0;
  int min_subscribers_ = 3;
  std::string frame_id_;
  double position_ = 5.5;
  double velocity_ = 0.1;
  std::string output_;

  ros::Publisher publisher_;
  std::vector<ros::Subscriber> subscribers_;
  /// The subscribers of relative_measurement in the order they connected: the order in which
  /// publish() writes to them (each write delays the next subscriber's copy a little).
  std::mutex order_mutex_;
  std::vector<std::string> send_order_;
  // Written by the publishing thread, read after it is joined.
  std::uint64_t published_ = 0;
  std::uint64_t skipped_ = 0;
  std::int64_t window_start_ = 0;
  std::int64_t window_end_ = -1;
  std::vector<double> publish_delays_;  ///< us after the due time, of the measured publishes
  std::unique_ptr<Recorder<Arrival>> relay_;
  std::unique_ptr<Recorder<Arrival>> measurement_command_;
  std::unique_ptr<Recorder<Arrival>> timer_command_;
  std::unique_ptr<Recorder<StatusSample>> measurement_status_;
  std::unique_ptr<Recorder<StatusSample>> timer_status_;
};

}  // namespace

int main(int argc, char** argv) {
  ros::init(argc, argv, "latency_probe");
  int code = 2;
  {
    LatencyProbe probe{ros::NodeHandle(), ros::NodeHandle("~")};
    code = probe.run();
  }
  ros::shutdown();
  return code;
}
