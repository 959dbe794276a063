/// The main() of the rostests' C++ programs (test/rostest/test_*.cpp; linked into each by
/// CMakeLists.txt): gtest's flags, then ros::init, then the tests.
///
/// The default node name is the program's file name (test_paper_run_ros, ...), the name each
/// program gave itself before; rostest remaps it to the <test>'s name anyway. No spinner runs
/// here: the fixtures spin in waitFor() (ros::spinOnce(), test_common.h), and a test that needs
/// a spinner of its own starts it. A program that needs something around all of its tests, after
/// ros::init (test_follower_loop's measurement source), registers a ::testing::Environment:
/// gtest sets it up at the start of RUN_ALL_TESTS() and runs no test if that fails.

#include <string>

#include <gtest/gtest.h>
#include <ros/ros.h>

namespace {

/// The base name of @p program (argv[0]) as a node name: "rostest" if it has none.
std::string nodeName(const char* program) {
  std::string name = program != nullptr ? program : "";
  const std::string::size_type slash = name.find_last_of('/');
  if (slash != std::string::npos) {
    name.erase(0, slash + 1);
  }
  for (char& c : name) {
    const bool valid =
        (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_';
    c = valid ? c : '_';
  }
  const bool starts_with_letter =
      !name.empty() && ((name[0] >= 'a' && name[0] <= 'z') || (name[0] >= 'A' && name[0] <= 'Z'));
  return starts_with_letter ? name : "rostest";
}

}  // namespace

int main(int argc, char** argv) {
  ::testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, nodeName(argc > 0 ? argv[0] : nullptr));
  return RUN_ALL_TESTS();
}
