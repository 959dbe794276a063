// InlineCallbackQueue: callbacks run at once on the adding thread, TryAgain retried, Invalid and
// unready callbacks dropped. No master: roscpp's callback interface only.
#include <deque>
#include <thread>

#include <boost/make_shared.hpp>
#include <gtest/gtest.h>

#include "projection_collision_avoidance/ros/InlineCallbackQueue.hpp"

namespace projection_collision_avoidance {
namespace {

/// Answers the scripted results in turn (then Success), noting the thread of each call.
class ScriptedCallback : public ros::CallbackInterface {
 public:
  explicit ScriptedCallback(std::deque<CallResult> script, bool ready = true)
      : script_(std::move(script)), ready_(ready) {}
  CallResult call() override {
    ++calls;
    thread = std::this_thread::get_id();
    if (script_.empty()) {
      return Success;
    }
    const CallResult result = script_.front();
    script_.pop_front();
    return result;
  }
  bool ready() override { return ready_; }
  int calls = 0;
  std::thread::id thread;

 private:
  std::deque<CallResult> script_;
  bool ready_;
};

TEST(InlineCallbackQueue, RunsTheCallbackAtOnceOnTheAddingThread) {
  InlineCallbackQueue queue;
  auto callback =
      boost::make_shared<ScriptedCallback>(std::deque<ros::CallbackInterface::CallResult>{});
  queue.addCallback(callback, 1);
  EXPECT_EQ(callback->calls, 1);
  EXPECT_EQ(callback->thread, std::this_thread::get_id());
  std::thread other([&] { queue.addCallback(callback, 1); });
  const std::thread::id other_id = other.get_id();
  other.join();
  EXPECT_EQ(callback->calls, 2);
  EXPECT_EQ(callback->thread, other_id);
  EXPECT_EQ(queue.called(), 2U);
  EXPECT_EQ(queue.retried(), 0U);
  EXPECT_EQ(queue.dropped(), 0U);
}

TEST(InlineCallbackQueue, TriesAgainUntilTheCallbackRuns) {
  InlineCallbackQueue queue;
  auto callback =
      boost::make_shared<ScriptedCallback>(std::deque<ros::CallbackInterface::CallResult>{
          ros::CallbackInterface::TryAgain, ros::CallbackInterface::TryAgain,
          ros::CallbackInterface::TryAgain});
  queue.addCallback(callback, 7);
  EXPECT_EQ(callback->calls, 4);
  EXPECT_EQ(queue.called(), 1U);
  EXPECT_EQ(queue.retried(), 3U);
}

TEST(InlineCallbackQueue, DropsInvalidAndUnreadyCallbacks) {
  InlineCallbackQueue queue;
  auto invalid = boost::make_shared<ScriptedCallback>(
      std::deque<ros::CallbackInterface::CallResult>{ros::CallbackInterface::Invalid});
  queue.addCallback(invalid, 1);
  EXPECT_EQ(invalid->calls, 1);
  auto unready =
      boost::make_shared<ScriptedCallback>(std::deque<ros::CallbackInterface::CallResult>{},
                                           /*ready=*/false);
  queue.addCallback(unready, 1);
  EXPECT_EQ(unready->calls, 0);
  queue.addCallback(ros::CallbackInterfacePtr(), 1);
  queue.removeByID(1);  // nothing queued: nothing to remove, nothing run
  EXPECT_EQ(queue.called(), 0U);
  EXPECT_EQ(queue.dropped(), 3U);
}

}  // namespace
}  // namespace projection_collision_avoidance
