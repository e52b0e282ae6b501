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
  EXPECT_EQ(runTool("--world urban --trajectory straight --frames 2 --sensor hdl128" + out), 2);
  EXPECT_EQ(runTool("--world urban --trajectory straight --frames 2 --dropout 1.5" + out), 2);
  EXPECT_EQ(runTool("--world urban --trajectory straight --frames 2 --deskewed yes" + out), 2);
  EXPECT_EQ(runTool("--world urban --trajectory straight --frames 2 --deskewed 0 --time-convention gps" + out), 2);
  // An instantaneous scan has no times to tell.
  EXPECT_EQ(runTool("--world urban --trajectory straight --frames 2 --time-convention azimuth" + out), 2);
  EXPECT_EQ(runTool("--world urban --trajectory straight --frames 2 --format ply" + out), 2);
  EXPECT_EQ(runTool("--world urban --trajectory straight --frames 2 --beam-range-bias -0.01" + out), 2);
  EXPECT_EQ(runTool("--world urban --trajectory straight --frames 2 --beam-elevation-error -1" + out), 2);
  EXPECT_EQ(runTool("--world urban --trajectory straight --frames 2 --range-offset 5cm" + out), 2);
  EXPECT_EQ(runTool("--world urban --trajectory straight --frames 2 --range-offset 2" + out), 2);
  EXPECT_EQ(runTool("--world urban --poses /nonexistent/poses.txt" + out), 2);
  EXPECT_EQ(runTool("--world urban --trajectory straight --frames 2 --gait hop" + out), 2);
  EXPECT_EQ(runTool("--world urban --trajectory straight --frames 2 --stamp-rounding -0.01" + out), 2);
  EXPECT_EQ(runTool("--world urban --trajectory straight --frames 2 --truth-time-offset nan" + out), 2);
  EXPECT_EQ(runTool("--world urban --trajectory straight --frames 2 --truth-time-offset 10ms" + out), 2);
  EXPECT_EQ(runTool("--world urban --trajectory straight --frames 2 --truth-at oxts" + out), 2);
  EXPECT_EQ(runTool("--world urban --trajectory straight --frames 2 --bag" + out), 2);  // --bag without a file
  EXPECT_EQ(runTool("--world urban --trajectory straight --frames 2"), 2);               // no output
  EXPECT_FALSE(std::filesystem::exists(directory.file("seq")));
}

TEST(EloSimCli, WritesASequence) {
  const elo::test::TempDirectory directory;
  EXPECT_EQ(runTool("--world parking --trajectory uturn --frames 3 --sensor vlp16 --seed 9 --noise 0.01 "
                    "--dropout 0.05 --deskewed 0 --moving-cars 2 --beam-range-bias 0.01 --beam-elevation-error 0.05 "
                    "--range-offset -0.02 --lower-block-rise 0.03 --gait walk "
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

std::set<std::string> fieldNamesWithTime() { return {"x", "y", "z", "intensity", "ring", "time"}; }

// The bag holds the scans written to disk, at their times (+1 s, as kitti_to_bag), with every field a
// driver publishes for a sweep with motion (the field convention is the default), and the ground truth
// of poses.txt.
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
    EXPECT_EQ(fieldNames(*cloud), fieldNamesWithTime());
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

// Which fields and stamps a bag's clouds get: times only for a sweep with motion in the field
// convention; the azimuth convention stamps each scan at mid-sweep, with its ground truth.
TEST(EloSimCli, BagTimesFollowTheTimeConvention) {
  const elo::test::TempDirectory directory;
  const std::set<std::string> without_time = {"x", "y", "z", "intensity", "ring"};
  struct Case {
    std::string options;
    std::set<std::string> fields;
    double reference_offset;  // of the stamps from the sweeps' starts
  };
  const std::vector<Case> cases = {{"", without_time, 0.0},
                                   {"--deskewed 0 --time-convention field", fieldNamesWithTime(), 0.0},
                                   {"--deskewed 0 --time-convention azimuth", without_time, 0.05}};
  for (size_t c = 0; c < cases.size(); ++c) {
    const std::string name = "case" + std::to_string(c);
    ASSERT_EQ(runTool("--world urban --trajectory straight --frames 2 --sensor vlp16 " + cases[c].options +
                      " --output " + directory.file(name) + " --bag " + directory.file(name + ".bag")),
              0)
        << cases[c].options;
    rosbag::Bag bag(directory.file(name + ".bag"), rosbag::bagmode::Read);
    size_t scan = 0;
    for (const rosbag::MessageInstance& message : rosbag::View(bag, rosbag::TopicQuery("/points"))) {
      const auto cloud = message.instantiate<sensor_msgs::PointCloud2>();
      ASSERT_TRUE(cloud);
      EXPECT_EQ(fieldNames(*cloud), cases[c].fields) << cases[c].options;
      EXPECT_NEAR(cloud->header.stamp.toSec(), 1.0 + 0.1 * scan + cases[c].reference_offset, 1e-6) << cases[c].options;
      ++scan;
    }
    EXPECT_EQ(scan, 2u);
  }
}

// --format pcd: the flat layout, the scans with their ring and times.
TEST(EloSimCli, WritesPcdScans) {
  const elo::test::TempDirectory directory;
  ASSERT_EQ(runTool("--world urban --trajectory straight --frames 2 --sensor vlp16 --deskewed 0 --format pcd "
                    "--output " + directory.file("seq")),
            0);
  EXPECT_FALSE(std::filesystem::exists(directory.file("seq/velodyne")));
  const elo::Sequence sequence(directory.file("seq"));
  ASSERT_EQ(sequence.size(), 2u);
  const elo::PointCloud cloud = sequence.load(1);
  EXPECT_EQ(cloud.time.size(), cloud.size());
  EXPECT_EQ(cloud.ring.size(), cloud.size());
  EXPECT_EQ(sequence.groundTruth().size(), 2u);
}

}  // namespace
