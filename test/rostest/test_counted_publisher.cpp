// CountedPublisher: its count follows the subscribers that come and go, in this process and in
// another (test/rostest/counted_publisher.test starts a topic_tools relay subscribing to "remote"),
// and through copies.
#include <atomic>
#include <chrono>
#include <functional>
#include <thread>
#include <vector>

#include <gtest/gtest.h>
#include <ros/ros.h>
#include <std_msgs/UInt32.h>

#include "projection_collision_avoidance/ros/CountedPublisher.hpp"

namespace projection_collision_avoidance {
namespace {

/// Spins until @p condition holds or ~deadline s (wall) pass; returns whether it held.
bool waitFor(const std::function<bool()>& condition) {
  const double deadline = ros::param::param("~deadline", 10.0);
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(deadline);
  while (std::chrono::steady_clock::now() < end && ros::ok()) {
    ros::spinOnce();
    if (condition()) {
      return true;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  return condition();
}

TEST(CountedPublisher, CountsSubscribersInThisProcess) {
  ros::NodeHandle nh;
  CountedPublisher publisher;
  publisher.advertise<std_msgs::UInt32>(nh, "local", 10);
  EXPECT_FALSE(publisher.subscribed());
  std::atomic<int> received{0};
  const auto count = [&received](const std_msgs::UInt32::ConstPtr&) { ++received; };
  ros::Subscriber first = nh.subscribe<std_msgs::UInt32>("local", 10, count);
  ASSERT_TRUE(waitFor([&] { return publisher.subscribers() == 1; }));
  // A process's subscribers to one topic share one connection: still one.
  ros::Subscriber second = nh.subscribe<std_msgs::UInt32>("local", 10, count);
  publisher.publish(boost::make_shared<std_msgs::UInt32>());
  ASSERT_TRUE(waitFor([&] { return received == 2; }));
  EXPECT_EQ(publisher.subscribers(), 1);
  first.shutdown();
  publisher.publish(boost::make_shared<std_msgs::UInt32>());
  ASSERT_TRUE(waitFor([&] { return received == 3; }));
  EXPECT_TRUE(publisher.subscribed());
  second.shutdown();
  ASSERT_TRUE(waitFor([&] { return publisher.subscribers() == 0; }));
  EXPECT_FALSE(publisher.subscribed());
}

TEST(CountedPublisher, CountsASubscriberInAnotherProcess) {
  ros::NodeHandle nh;
  CountedPublisher publisher;
  publisher.advertise<std_msgs::UInt32>(nh, "remote", 10);
  // The relay subscribes to "remote" and republishes it on "remote_copy".
  ASSERT_TRUE(waitFor([&] { return publisher.subscribers() == 1; }))
      << "no subscriber counted on " << publisher.topic();
  std::atomic<std::uint32_t> copied{0};
  ros::Subscriber copy = nh.subscribe<std_msgs::UInt32>(
      "remote_copy", 10, [&copied](const std_msgs::UInt32::ConstPtr& msg) { copied = msg->data; });
  auto message = boost::make_shared<std_msgs::UInt32>();
  message->data = 7;
  ASSERT_TRUE(waitFor([&] {
    publisher.publish(message);
    return copied == 7U;
  }));
}

TEST(CountedPublisher, ACopyKeepsCounting) {
  // The plant keeps its publishers in a vector that grows: a copy must count as the original.
  ros::NodeHandle nh;
  std::vector<CountedPublisher> publishers(1);
  publishers[0].advertise<std_msgs::UInt32>(nh, "copied", 10);
  publishers.resize(64);  // moves the first one
  std::atomic<int> received{0};
  ros::Subscriber subscriber = nh.subscribe<std_msgs::UInt32>(
      "copied", 10, [&received](const std_msgs::UInt32::ConstPtr&) { ++received; });
  ASSERT_TRUE(waitFor([&] { return publishers[0].subscribed(); }));
  EXPECT_FALSE(publishers[1].subscribed());  // never advertised
  publishers[0].publish(boost::make_shared<std_msgs::UInt32>());
  EXPECT_TRUE(waitFor([&] { return received == 1; }));
}

}  // namespace
}  // namespace projection_collision_avoidance
