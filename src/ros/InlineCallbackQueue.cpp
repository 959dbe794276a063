#include "projection_collision_avoidance/ros/InlineCallbackQueue.hpp"

#include <thread>

namespace projection_collision_avoidance {

void InlineCallbackQueue::addCallback(const ros::CallbackInterfacePtr& callback,
                                      uint64_t /*owner_id*/) {
  if (!callback || !callback->ready()) {
    dropped_.fetch_add(1, std::memory_order_relaxed);
    return;
  }
  while (true) {
    switch (callback->call()) {
      case ros::CallbackInterface::Success:
        called_.fetch_add(1, std::memory_order_relaxed);
        return;
      case ros::CallbackInterface::TryAgain:  // its previous call runs on another thread
        retried_.fetch_add(1, std::memory_order_relaxed);
        std::this_thread::yield();
        break;
      case ros::CallbackInterface::Invalid:
        dropped_.fetch_add(1, std::memory_order_relaxed);
        return;
    }
  }
}

void InlineCallbackQueue::removeByID(uint64_t /*owner_id*/) {}

}  // namespace projection_collision_avoidance
