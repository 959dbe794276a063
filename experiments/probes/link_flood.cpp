/// Other traffic on a link (experiments/link/run.sh): ~mode publish sends std_msgs/UInt8MultiArray
/// messages of ~bytes bytes on `flood` at ~rate Hz from a thread of its own (absolute deadlines on
/// CLOCK_MONOTONIC; a wake-up a period late skips the periods it missed); ~mode subscribe (TCP)
/// counts them. Each runs for ~duration s, then logs "link_flood: <mode> <count> messages, <rate>
/// Hz" and exits 0 (2: bad parameters).

#include <atomic>
#include <cstdint>
#include <string>

#include <ros/ros.h>
#include <std_msgs/UInt8MultiArray.h>
#include <time.h>

namespace {

constexpr std::int64_t kNsPerS = 1000000000;

std::int64_t monotonicNs() {
  timespec t{};
  clock_gettime(CLOCK_MONOTONIC, &t);
  return static_cast<std::int64_t>(t.tv_sec) * kNsPerS + t.tv_nsec;
}

void sleepUntil(std::int64_t ns) {
  const timespec t{static_cast<time_t>(ns / kNsPerS), static_cast<long>(ns % kNsPerS)};
  while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &t, nullptr) != 0) {
  }
}

std::uint64_t publish(ros::NodeHandle& nh, double rate, int bytes, double duration) {
  ros::Publisher pub = nh.advertise<std_msgs::UInt8MultiArray>("flood", 100);
  std_msgs::UInt8MultiArray msg;
  msg.data.assign(static_cast<std::size_t>(bytes), 0x5a);
  const auto period = static_cast<std::int64_t>(1e9 / rate);
  const std::int64_t start = monotonicNs();
  const std::int64_t end = start + static_cast<std::int64_t>(duration * 1e9);
  std::uint64_t sent = 0;
  for (std::int64_t due = start; due < end && ros::ok(); due += period) {
    const std::int64_t now = monotonicNs();
    if (now > due + period) {
      due += ((now - due) / period) * period;  // skip the missed periods
    }
    sleepUntil(due);
    pub.publish(msg);
    ++sent;
  }
  return sent;
}

std::uint64_t subscribe(ros::NodeHandle& nh, double duration) {
  std::atomic<std::uint64_t> received{0};
  ros::Subscriber sub = nh.subscribe<std_msgs::UInt8MultiArray>(
      "flood", 1000, [&received](const std_msgs::UInt8MultiArray::ConstPtr&) { ++received; }, {},
      ros::TransportHints().tcpNoDelay());
  ros::AsyncSpinner spinner(1);
  spinner.start();
  ros::WallDuration(duration).sleep();
  spinner.stop();
  return received.load();
}

}  // namespace

int main(int argc, char** argv) {
  ros::init(argc, argv, "link_flood");
  ros::NodeHandle nh;
  ros::NodeHandle pnh("~");
  const std::string mode = pnh.param<std::string>("mode", "publish");
  const double rate = pnh.param("rate", 10000.0);
  const int bytes = pnh.param("bytes", 1000);
  const double duration = pnh.param("duration", 30.0);
  if ((mode != "publish" && mode != "subscribe") || !(rate > 0.0) || bytes < 0 ||
      !(duration > 0.0)) {
    ROS_FATAL("link_flood: ~mode publish|subscribe, ~rate > 0, ~bytes >= 0, ~duration > 0");
    return 2;
  }
  const std::uint64_t count =
      mode == "publish" ? publish(nh, rate, bytes, duration) : subscribe(nh, duration);
  ROS_INFO("link_flood: %s %llu messages, %.1f Hz", mode.c_str(),
           static_cast<unsigned long long>(count), static_cast<double>(count) / duration);
  return 0;
}
