#include "projection_collision_avoidance/ros/GuardedTransformListener.hpp"

#include <cmath>
#include <sstream>
#include <utility>

#include <tf2/exceptions.h>

#include "projection_collision_avoidance/ros/InputAdmission.hpp"

namespace projection_collision_avoidance {
namespace {

constexpr double kQuaternionTolerance = 1e-3;
/// s the listener's thread waits for a message before it checks whether to stop.
constexpr double kSpinWait = 0.01;

bool finiteTransform(const geometry_msgs::Transform& t) {
  const double norm = std::sqrt(t.rotation.x * t.rotation.x + t.rotation.y * t.rotation.y +
                                t.rotation.z * t.rotation.z + t.rotation.w * t.rotation.w);
  return std::isfinite(t.translation.x) && std::isfinite(t.translation.y) &&
         std::isfinite(t.translation.z) && std::abs(norm - 1.0) <= kQuaternionTolerance;
}

}  // namespace

GuardedTransformListener::GuardedTransformListener(tf2_ros::Buffer* buffer, ros::NodeHandle nh,
                                                   const TransformGuardOptions& options,
                                                   std::string node_name)
    : buffer_(buffer),
      options_(options),
      name_(std::move(node_name)),
      guard_("tf", InputGuardLimits{}) {
  buffer_->setUsingDedicatedThread(true);  // lookups with a timeout wait for this thread
  const ros::TransportHints hints = ros::TransportHints().tcpNoDelay();
  using Event = ros::MessageEvent<tf2_msgs::TFMessage const>;
  dynamic_subscriber_ = subscribeEvents<tf2_msgs::TFMessage>(
      nh, "/tf", 100, [this](const Event& event) { onMessage(event, false); }, hints, &queue_);
  static_subscriber_ = subscribeEvents<tf2_msgs::TFMessage>(
      nh, "/tf_static", 100, [this](const Event& event) { onMessage(event, true); }, hints,
      &queue_);
  thread_ = std::thread([this] {
    while (!stop_.load(std::memory_order_relaxed) && ros::ok()) {
      queue_.callAvailable(ros::WallDuration(kSpinWait));
    }
  });
}

GuardedTransformListener::~GuardedTransformListener() {
  stop_.store(true, std::memory_order_relaxed);
  dynamic_subscriber_.shutdown();
  static_subscriber_.shutdown();
  if (thread_.joinable()) {
    thread_.join();
  }
}

void GuardedTransformListener::onMessage(const ros::MessageEvent<tf2_msgs::TFMessage const>& event,
                                         bool is_static) {
  const std::lock_guard<std::mutex> lock(mutex_);
  admitGuarded(guard_, name_, [&] {
    const ros::Time now = ros::Time::now();
    const std::int64_t now_ns = nanosecondsOf(now);
    if (wentBack(clock_, now)) {
      ROS_WARN_STREAM(name_ << ": ROS time went back; clearing the tf buffer");
      buffer_->clear();
    }
    const std::string& authority = publisherOf(event);
    for (const geometry_msgs::TransformStamped& t : event.getConstMessage()->transforms) {
      if (!admit(t, now_ns, is_static)) {
        rejected_.store(guard_.rejected(), std::memory_order_relaxed);
        continue;
      }
      try {
        buffer_->setTransform(t, authority, is_static);
      } catch (const tf2::TransformException& error) {
        guard_.reject(Rejection::kContent, error.what());
        rejected_.store(guard_.rejected(), std::memory_order_relaxed);
      }
    }
  });
}

bool GuardedTransformListener::admit(const geometry_msgs::TransformStamped& t, std::int64_t now_ns,
                                     bool is_static) {
  const std::string& child = t.child_frame_id;
  if (t.header.frame_id.empty() || child.empty() || !finiteTransform(t.transform)) {
    guard_.reject(Rejection::kContent,
                  "transform to '" + boundedText(child, InputGuard::kMaxQuotedLength) +
                      "': an unnamed frame, a non-finite translation or a rotation that is not "
                      "a unit quaternion");
    return false;
  }
  if (is_static) {
    return true;  // a static transform holds at every time: its stamp is not judged
  }
  const std::int64_t stamp_ns = nanosecondsOf(t.header.stamp);
  if (stamp_ns == 0) {
    guard_.reject(Rejection::kZeroStamp,
                  "transform to '" + boundedText(child, InputGuard::kMaxQuotedLength) + "'");
    return false;
  }
  const double ahead = 1e-9 * static_cast<double>(stamp_ns - now_ns);
  if (ahead > options_.max_future_stamp || -ahead > buffer_->getCacheLength().toSec()) {
    std::ostringstream why;
    why << "transform to '" << boundedText(child, InputGuard::kMaxQuotedLength) << "' stamped "
        << ahead << " s from the clock (at most " << options_.max_future_stamp << " ahead and "
        << buffer_->getCacheLength().toSec() << " behind: the tf buffer's cache)";
    guard_.reject(ahead > 0.0 ? Rejection::kFuture : Rejection::kStale, why.str());
    return false;
  }
  return true;
}

}  // namespace projection_collision_avoidance
