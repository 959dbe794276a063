/// ReleaseQueue: payloads released by due time (ties in arrival order), not blocked by one held
/// far ahead; bounded in count and in bytes, dropping the oldest.

#include <cstddef>
#include <stdexcept>
#include <vector>

#include <gtest/gtest.h>

#include "projection_collision_avoidance/sim/ReleaseQueue.hpp"

namespace projection_collision_avoidance {
namespace {

/// The payloads due at @p horizon (s), in release order.
std::vector<int> releaseDue(ReleaseQueue<int>* queue, double horizon) {
  std::vector<int> out;
  while (!queue->empty() && queue->nextRelease() <= horizon) {
    out.push_back(queue->pop());
  }
  return out;
}

TEST(ReleaseQueue, AFarFuturePayloadDoesNotDelayLaterOnes) {
  ReleaseQueue<int> queue(100, 1 << 20);
  queue.push(1e9, 10, 0);  // released in 30 years
  for (int k = 1; k <= 5; ++k) {
    queue.push(0.1 * k, 10, k);
  }
  EXPECT_EQ(releaseDue(&queue, 0.25), (std::vector<int>{1, 2}));
  EXPECT_EQ(releaseDue(&queue, 1.0), (std::vector<int>{3, 4, 5}));
  EXPECT_EQ(queue.size(), 1U);
  EXPECT_EQ(queue.bytes(), 10U);
  EXPECT_EQ(releaseDue(&queue, 1e9), (std::vector<int>{0}));
  EXPECT_TRUE(queue.empty());
  EXPECT_EQ(queue.bytes(), 0U);
}

TEST(ReleaseQueue, OutOfOrderReleasesComeOutInOrderAndTiesInArrivalOrder) {
  ReleaseQueue<int> queue(100, 1 << 20);
  const double releases[] = {0.3, 0.1, 0.2, 0.1, 0.3, 0.1};
  for (int k = 0; k < 6; ++k) {
    queue.push(releases[k], 1, k);
  }
  EXPECT_EQ(releaseDue(&queue, 1.0), (std::vector<int>{1, 3, 5, 2, 0, 4}));
}

TEST(ReleaseQueue, TheByteBoundDropsTheOldestAndRefusesWhatCannotFit) {
  ReleaseQueue<int> queue(100, 1000);
  // Released in reverse of arrival: the oldest is the last due, and still the first dropped.
  for (int k = 0; k < 4; ++k) {
    const auto result = queue.push(10.0 - k, 300, k);
    EXPECT_TRUE(result.accepted);
    EXPECT_EQ(result.dropped, k == 3 ? 1U : 0U) << k;
    EXPECT_LE(queue.bytes(), 1000U);
  }
  EXPECT_EQ(queue.bytes(), 900U);
  // 700 bytes: the two oldest left go.
  const auto big = queue.push(5.0, 700, 4);
  EXPECT_TRUE(big.accepted);
  EXPECT_EQ(big.dropped, 2U);
  EXPECT_EQ(queue.bytes(), 1000U);
  EXPECT_EQ(releaseDue(&queue, 100.0), (std::vector<int>{4, 3}));
  // Larger than the bound alone: refused, nothing dropped.
  queue.push(1.0, 10, 5);
  const auto huge = queue.push(1.0, 1001, 6);
  EXPECT_FALSE(huge.accepted);
  EXPECT_EQ(huge.dropped, 0U);
  EXPECT_EQ(releaseDue(&queue, 100.0), (std::vector<int>{5}));
}

TEST(ReleaseQueue, TheCountBoundDropsTheOldest) {
  ReleaseQueue<int> queue(3, 1 << 20);
  for (int k = 0; k < 5; ++k) {
    queue.push(1.0, 1, k);
  }
  EXPECT_EQ(queue.size(), 3U);
  EXPECT_EQ(releaseDue(&queue, 1.0), (std::vector<int>{2, 3, 4}));
  EXPECT_THROW(ReleaseQueue<int>(0, 1), std::invalid_argument);
  EXPECT_THROW(ReleaseQueue<int>(1, 0), std::invalid_argument);
}

TEST(ReleaseQueue, ManyPayloadsStayWithinBothBoundsAndComeOutSorted) {
  ReleaseQueue<int> queue(64, 5000);
  std::size_t dropped = 0;
  for (int k = 0; k < 1000; ++k) {
    const double release = static_cast<double>((k * 7919) % 101);
    dropped += queue.push(release, static_cast<std::size_t>(50 + (k * 31) % 200), k).dropped;
    ASSERT_LE(queue.size(), 64U);
    ASSERT_LE(queue.bytes(), 5000U);
  }
  EXPECT_GT(dropped, 900U);
  double last = -1.0;
  while (!queue.empty()) {
    const double release = queue.nextRelease();
    EXPECT_GE(release, last);
    last = release;
    queue.pop();
  }
  EXPECT_EQ(queue.bytes(), 0U);
}

}  // namespace
}  // namespace projection_collision_avoidance
