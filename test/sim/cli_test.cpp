// The elo_sim command line: help, clear errors with exit code 2, and small runs to disk and to a bag.
#include <gtest/gtest.h>
#include <nav_msgs/Odometry.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <sensor_msgs/PointCloud2.h>
#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <set>

#include "../io/temp_directory.hpp"
#include "elo/io/sequence.hpp"

namespace {

int runTool(const std::string& arguments) {
  const std::string command = std::string(ELO_SIM_TOOL) + " " + arguments + " >/dev/null 2>&1";
  const int status = std::system(command.c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

TEST(EloSimCli, HelpSucceeds) { EXPECT_EQ(runTool("--help"), 0); }

TEST(EloSimCli, BadArgumentsExitWithTwo) {
  const elo::test::TempDirectory directory;
  const std::string out = " --output " + directory.file("seq");
  EXPECT_EQ(runTool("--trajectory straight --frames 2" + out), 2);                       // no world
  EXPECT_EQ(runTool("--world moon --trajectory straight --frames 2" + out), 2);          // unknown world
  EXPECT_EQ(runTool("--world urban --trajectory spiral --frames 2" + out), 2);           // unknown trajectory
  EXPECT_EQ(runTool("--world urban --frames 2" + out), 2);                               // no trajectory
  EXPECT_EQ(runTool("--world urban --trajectory straight --poses x.txt --frames 2" + out), 2);  // both
  EXPECT_EQ(runTool("--world urban --trajectory straight --frames two" + out), 2);
  EXPECT_EQ(runTool("--world urban --trajectory straight --frames 0" + out), 2);
  EXPECT_EQ(runTool("--world urban --trajectory straight" + out), 2);                    // no frame count
  EXPECT_EQ(runTool("--world urban --trajectory straight --frames 2 --sensor hdl32" + out), 2);
  EXPECT_EQ(runTool("--world urban --trajectory straight --frames 2 --dropout 1.5" + out), 2);
  EXPECT_EQ(runTool("--world urban --trajectory straight --frames 2 --deskewed yes" + out), 2);
  EXPECT_EQ(runTool("--world urban --trajectory straight --frames 2 --beam-range-bias -0.01" + out), 2);
  EXPECT_EQ(runTool("--world urban --trajectory straight --frames 2 --beam-elevation-error -1" + out), 2);
  EXPECT_EQ(runTool("--world urban --poses /nonexistent/poses.txt" + out), 2);
  EXPECT_EQ(runTool("--world urban --trajectory straight --frames 2 --bag" + out), 2);  // --bag without a file
  EXPECT_EQ(runTool("--world urban --trajectory straight --frames 2"), 2);               // no output
  EXPECT_FALSE(std::filesystem::exists(directory.file("seq")));
}

TEST(EloSimCli, WritesASequence) {
  const elo::test::TempDirectory directory;
  EXPECT_EQ(runTool("--world parking --trajectory uturn --frames 3 --sensor vlp16 --seed 9 --noise 0.01 "
                    "--dropout 0.05 --deskewed 0 --moving-cars 2 --beam-range-bias 0.01 --beam-elevation-error 0.05 "
                    "--threads 2 --output " + directory.file("seq")),
            0);
  for (const std::string file : {"velodyne/000000.bin", "velodyne/000002.bin", "poses.txt", "times.txt", "calib.txt"}) {
    EXPECT_TRUE(std::filesystem::exists(directory.file("seq/" + file))) << file;
  }
}

std::set<std::string> fieldNames(const sensor_msgs::PointCloud2& cloud) {
  std::set<std::string> names;
  for (const auto& field : cloud.fields) names.insert(field.name);
  return names;
}

// The bag holds the scans written to disk, at their times (+1 s, as kitti_to_bag), with every field a
// driver publishes for a sweep with motion, and the ground truth of poses.txt.
TEST(EloSimCli, WritesABag) {
  const elo::test::TempDirectory directory;
  const std::string bag_path = directory.file("seq.bag");
  ASSERT_EQ(runTool("--world urban --trajectory curves --frames 3 --sensor vlp16 --deskewed 0 --output " +
                    directory.file("seq") + " --bag " + bag_path),
            0);
  const elo::Sequence sequence(directory.file("seq"));
  rosbag::Bag bag(bag_path, rosbag::bagmode::Read);

  size_t scan = 0;
  for (const rosbag::MessageInstance& message : rosbag::View(bag, rosbag::TopicQuery("/points"))) {
    const auto cloud = message.instantiate<sensor_msgs::PointCloud2>();
    ASSERT_TRUE(cloud);
    ASSERT_LT(scan, sequence.size());
    EXPECT_EQ(cloud->header.frame_id, "velodyne");
    EXPECT_NEAR(cloud->header.stamp.toSec(), sequence.stamp(scan) + 1.0, 1e-6);
    EXPECT_EQ(size_t{cloud->width} * cloud->height, sequence.load(scan).size());
    EXPECT_EQ(fieldNames(*cloud), (std::set<std::string>{"x", "y", "z", "intensity", "ring", "time"}));
    ++scan;
  }
  EXPECT_EQ(scan, 3u);

  size_t pose = 0;
  for (const rosbag::MessageInstance& message : rosbag::View(bag, rosbag::TopicQuery("/ground_truth"))) {
    const auto odometry = message.instantiate<nav_msgs::Odometry>();
    ASSERT_TRUE(odometry);
    ASSERT_LT(pose, sequence.size());
    const Eigen::Vector3d expected = sequence.groundTruth()[pose].translation();
    EXPECT_NEAR(odometry->pose.pose.position.x, expected.x(), 1e-9);
    EXPECT_NEAR(odometry->pose.pose.position.y, expected.y(), 1e-9);
    EXPECT_NEAR(odometry->pose.pose.position.z, expected.z(), 1e-9);
    ++pose;
  }
  EXPECT_EQ(pose, 3u);
}

}  // namespace
