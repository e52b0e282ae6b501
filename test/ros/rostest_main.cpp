// The main() of every rostest node (elo_add_rostest): gtest, then ROS, under the executable's name
// (rostest names the node after the .test file's test-name anyway), with two threads spinning so that
// the subscriptions a test waits on are served while it waits.
#include <gtest/gtest.h>
#include <ros/ros.h>

#include <filesystem>

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, std::filesystem::path(argv[0]).filename().string());
  ros::AsyncSpinner spinner(2);
  spinner.start();
  return RUN_ALL_TESTS();
}
