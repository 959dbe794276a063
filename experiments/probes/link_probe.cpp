/// Link probe (experiments/link/run.sh): what a subscriber of `measurement` (RelativeMeasurement)
/// on one host sees of a publisher on another, over TCPROS or UDPROS.
///
/// Parameters:
///   ~transport  tcp or udp (ros::TransportHints().unreliable().reliable() as the follower does)
///   ~start      s of ROS time (wall time: since the epoch) at which the window opens, so that
///   probes
///               on several hosts count the same measurements; 0 (default): ~warmup s from now
///   ~warmup     s before the window opens when ~start is 0 (default 3)
///   ~duration   s of the window (default 20)
///   ~output     file: one line per measurement stamped in the window, "stamp_ns receipt_ns",
///               receipt the time roscpp read the message off its socket
///               (ros::MessageEvent::getReceiptTime()), both on this host's ROS clock
/// After the window and a drain of 1 s it writes ~output and exits 0 (2: bad parameters).

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <mutex>
#include <string>
#include <utility>
#include <vector>

#include <ros/ros.h>

#include "projection_collision_avoidance/RelativeMeasurement.h"

namespace {

using projection_collision_avoidance::RelativeMeasurement;

class LinkProbe {
 public:
  LinkProbe(ros::NodeHandle& nh, const ros::TransportHints& hints, double duration)
      : capacity_(static_cast<std::size_t>(duration * 20000.0) + 1000) {
    arrivals_.reserve(capacity_);
    subscriber_ = nh.subscribe<RelativeMeasurement>(
        "measurement", 1000,
        [this](const ros::MessageEvent<RelativeMeasurement const>& event) { add(event); }, {},
        hints);
  }

  /// Measurements stamped in [start, end), as (stamp, receipt) in ns.
  std::vector<std::pair<std::int64_t, std::int64_t>> window(std::int64_t start, std::int64_t end) {
    const std::lock_guard<std::mutex> lock(mutex_);
    std::vector<std::pair<std::int64_t, std::int64_t>> in;
    for (const auto& a : arrivals_) {
      if (a.first >= start && a.first < end) {
        in.push_back(a);
      }
    }
    return in;
  }

 private:
  void add(const ros::MessageEvent<RelativeMeasurement const>& event) {
    const std::lock_guard<std::mutex> lock(mutex_);
    if (arrivals_.size() < capacity_) {
      arrivals_.emplace_back(static_cast<std::int64_t>(event.getMessage()->header.stamp.toNSec()),
                             static_cast<std::int64_t>(event.getReceiptTime().toNSec()));
    }
  }

  std::size_t capacity_;
  std::mutex mutex_;
  std::vector<std::pair<std::int64_t, std::int64_t>> arrivals_;
  ros::Subscriber subscriber_;
};

}  // namespace

int main(int argc, char** argv) {
  ros::init(argc, argv, "link_probe");
  ros::NodeHandle nh;
  ros::NodeHandle pnh("~");
  const std::string transport = pnh.param<std::string>("transport", "tcp");
  const double warmup = pnh.param("warmup", 3.0);
  const double duration = pnh.param("duration", 20.0);
  const std::string output = pnh.param<std::string>("output", "");
  const double start_s = pnh.param("start", 0.0);
  if ((transport != "tcp" && transport != "udp") || output.empty() || !(duration > 0.0) ||
      !(warmup >= 0.0) || !(start_s >= 0.0)) {
    ROS_FATAL("link_probe: ~transport tcp|udp, ~output, ~duration > 0, ~warmup >= 0, ~start >= 0");
    return 2;
  }
  const ros::TransportHints hints = transport == "udp"
                                        ? ros::TransportHints().unreliable().reliable()
                                        : ros::TransportHints().tcpNoDelay();
  LinkProbe probe(nh, hints, duration);
  ros::AsyncSpinner spinner(1);
  spinner.start();
  const ros::WallTime begin = ros::WallTime::now();
  const auto now_ns = static_cast<std::int64_t>(ros::Time::now().toNSec());
  const std::int64_t start = start_s > 0.0 ? static_cast<std::int64_t>(start_s * 1e9)
                                           : now_ns + static_cast<std::int64_t>(warmup * 1e9);
  const std::int64_t end = start + static_cast<std::int64_t>(duration * 1e9);
  ros::WallDuration(std::max(0.0, 1e-9 * static_cast<double>(end - now_ns)) + 1.0).sleep();
  spinner.stop();
  const auto in = probe.window(start, end);
  std::FILE* file = std::fopen(output.c_str(), "w");
  if (file == nullptr) {
    ROS_FATAL_STREAM("link_probe: cannot write " << output);
    return 2;
  }
  for (const auto& [stamp, receipt] : in) {
    std::fprintf(file, "%lld %lld\n", static_cast<long long>(stamp),
                 static_cast<long long>(receipt));
  }
  std::fclose(file);
  ROS_INFO("link_probe (%s): %zu measurements in the window, %.1f s", transport.c_str(), in.size(),
           (ros::WallTime::now() - begin).toSec());
  return 0;
}
