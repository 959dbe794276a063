// Frame names as tf2 knows them (include/.../cycle/FrameNames.hpp): one leading slash dropped.
#include <string>

#include <gtest/gtest.h>

#include "projection_collision_avoidance/cycle/FrameNames.hpp"

namespace projection_collision_avoidance {
namespace {

TEST(FrameNames, DropOneLeadingSlashAsTf2Does) {
  EXPECT_EQ(tfFrameName("/robot_0/odom"), "robot_0/odom");
  EXPECT_EQ(tfFrameName("robot_0/odom"), "robot_0/odom");
  EXPECT_EQ(tfFrameName("//map"), "/map");
  EXPECT_EQ(tfFrameName("/"), "");
  EXPECT_EQ(tfFrameName(""), "");
  EXPECT_EQ(tfFrame("/world"), std::string("world"));
}

TEST(FrameNames, SameFrameUpToALeadingSlashEach) {
  EXPECT_TRUE(sameFrame("/robot_0/base_link", "robot_0/base_link"));
  EXPECT_TRUE(sameFrame("world", "/world"));
  EXPECT_TRUE(sameFrame("", ""));
  EXPECT_FALSE(sameFrame("world", "map"));
  EXPECT_FALSE(sameFrame("/world", "//world"));
  EXPECT_FALSE(sameFrame("world/", "world"));
}

TEST(FrameNames, AnOdometryLabelledWithItsOwnFrameNamesOneFrameTwice) {
  EXPECT_TRUE(labelledWithItsOwnFrame("robot_0", "robot_0"));
  EXPECT_TRUE(labelledWithItsOwnFrame("/robot_0/base_link", "robot_0/base_link"));
  EXPECT_FALSE(labelledWithItsOwnFrame("world", "robot_0/base_link"));
  EXPECT_FALSE(labelledWithItsOwnFrame("robot_0/odom", "robot_0/base_link"));
  // No name at all is no label: such a message is judged by its frames elsewhere.
  EXPECT_FALSE(labelledWithItsOwnFrame("", ""));
  EXPECT_FALSE(labelledWithItsOwnFrame("/", ""));
  EXPECT_FALSE(labelledWithItsOwnFrame("//a", "a"));
}

}  // namespace
}  // namespace projection_collision_avoidance
