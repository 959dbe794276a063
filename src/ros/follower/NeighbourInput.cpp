#include "follower/NeighbourInput.hpp"

#include "projection_collision_avoidance/ros/InputAdmission.hpp"
#include "projection_collision_avoidance/ros/MessageConversions.hpp"

namespace projection_collision_avoidance {

NeighbourInput::NeighbourInput(std::string node_name, const FollowerNodeOptions& options, int axes,
                               LatestValue<NeighbourSample>* slot)
    : name_(std::move(node_name)),
      axes_(axes),
      self_(options.agent_name),
      target_(options.target_name),
      slot_(slot),
      // As the relative measurement: an array older than its timeout on arrival is stale.
      timeline_("neighbours",
                {{options.measurement_frame, options.max_future_stamp, options.measurement_timeout},
                 options.clock_skew}) {
  order_.reserve(kMaxNeighbourEntries);
}

void NeighbourInput::start(ros::NodeHandle& nh, const ros::TransportHints& link) {
  subscriber_ = nh.subscribe("neighbours", 10, &NeighbourInput::onNeighbours, this, link);
}

std::string NeighbourInput::rejection() const {
  const std::lock_guard<std::mutex> lock(rejection_mutex_);
  return rejection_;
}

void NeighbourInput::onNeighbours(const ros::MessageEvent<NeighbourArray const>& event) {
  const NeighbourArray::ConstPtr& msg = event.getConstMessage();
  admitGuarded(timeline_, name_, [&] {
    const ros::Time now = ros::Time::now();
    if (!checkHeader(timeline_, msg->header, now, publisherOf(event))) {
      return;
    }
    std::string why;
    if (!neighbourSampleFromMsg(*msg, axes_, self_, target_, &sample_, &order_, &why)) {
      timeline_.reject(Rejection::kContent, why);
      return;
    }
    sample_.stamp_ns = timeline_.accept();  // on this clock (~clock_skew/policy)
    sample_.receipt_ns = nanosecondsOf(now);
    sample_.sequence = timeline_.guard().accepted();
    slot_->write(sample_);
  });
  const std::string& rejection = timeline_.guard().lastRejection();
  if (last_rejection_ != rejection) {
    last_rejection_ = rejection;
    const std::lock_guard<std::mutex> lock(rejection_mutex_);
    rejection_ = rejection;
  }
}

}  // namespace projection_collision_avoidance
