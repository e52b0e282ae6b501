// rostest (real_scans.test): the standalone node on the real HDL-64E scans of ../shared/data (a bag
// that kitti_to_bag made at test time); skipped, saying so, where the data is absent. Every scan gives
// odometry, the same as elo::Odometry in-process; ~save_trajectory, ~save_map, ~save_model and ~reset
// work. Prints
// the throughput at full replay speed and the latency of scans sent one at a time.
#include <diagnostic_msgs/DiagnosticArray.h>
#include <std_srvs/Trigger.h>

#include <boost/make_shared.hpp>

#include <algorithm>
#include <cstdio>
#include <numeric>

#include "elo/io/config_yaml.hpp"
#include "elo/io/kitti.hpp"
#include "elo/io/map_pcd.hpp"
#include "elo/io/pcd.hpp"
#include "rostest_helpers.hpp"

namespace {

using namespace elo_ros_test;

const std::string kData = ELO_ROS_TEST_DATA;
const std::string kRealScans = std::string(ELO_SHARED_DATA) + "/real/hdl64_drive_a";

std_srvs::Trigger::Response callTrigger(const std::string& service) {
  std_srvs::Trigger trigger;
  EXPECT_TRUE(ros::service::waitForService(service, ros::Duration(10.0))) << service;
  EXPECT_TRUE(ros::service::call(service, trigger)) << service;
  return trigger.response;
}

// The node's own latency figure (cloud received -> odometry published) from its diagnostics.
class ReportedLatency {
 public:
  explicit ReportedLatency(ros::NodeHandle& node)
      : subscriber_(node.subscribe("/diagnostics", 10, &ReportedLatency::onDiagnostics, this)) {}

  std::vector<double> windowMeans() {
    std::lock_guard<std::mutex> lock(mutex_);
    return means_;
  }

 private:
  void onDiagnostics(const diagnostic_msgs::DiagnosticArray& array) {
    for (const auto& status : array.status) {
      for (const auto& entry : status.values) {
        if (entry.key != "latency mean (ms)" || std::stod(entry.value) <= 0.0) continue;
        std::lock_guard<std::mutex> lock(mutex_);
        means_.push_back(std::stod(entry.value));
      }
    }
  }

  ros::Subscriber subscriber_;
  std::mutex mutex_;
  std::vector<double> means_;
};

double secondsSince(const ros::WallTime& start) { return (ros::WallTime::now() - start).toSec(); }

TEST(RealScans, StandaloneNodeOdometryAndServices) {
  if (!std::filesystem::is_directory(kRealScans)) {
    GTEST_SKIP() << "real scans not found at " << kRealScans << ": nothing to replay";
  }
  const std::string bag = kData + "/real.bag";
  ASSERT_TRUE(std::filesystem::exists(bag)) << bag << " is made by the ctest fixture ros_make_real_bag";
  const CloudMessages clouds = readClouds(bag, "/points");
  const elo::Sequence sequence(kRealScans);
  ASSERT_EQ(clouds.size(), sequence.size());

  ros::NodeHandle node;
  ros::Publisher points = node.advertise<sensor_msgs::PointCloud2>("points", clouds.size());
  OdometryRecorder recorder(node, "odom");
  ReportedLatency reported_latency(node);
  ASSERT_TRUE(waitForConnections(points, recorder, 30.0)) << "the node never connected";

  // Every scan at once, as a bag at full speed: the node queues them all (~process_every_scan).
  const ros::WallTime burst_start = ros::WallTime::now();
  for (const auto& cloud : clouds) points.publish(cloud);
  ASSERT_TRUE(recorder.waitFor(clouds.size(), 90.0)) << "got " << recorder.messages().size() << " odometry messages";
  const double burst_seconds = secondsSince(burst_start);
  std::printf("throughput at full replay speed: %zu scans in %.2f s = %.2f scans/s\n", clouds.size(), burst_seconds,
              clouds.size() / burst_seconds);
  ros::WallDuration(0.5).sleep();
  const std::vector<nav_msgs::Odometry> odometry = recorder.messages();
  ASSERT_EQ(odometry.size(), clouds.size()) << "one odometry message per scan";
  for (size_t i = 0; i < odometry.size(); ++i) {
    EXPECT_EQ(odometry[i].header.stamp, clouds[i]->header.stamp) << "scan " << i;
    EXPECT_EQ(odometry[i].child_frame_id, "velodyne") << "~publish_sensor_frame_directly";
  }

  elo::Config config;
  elo::loadConfigYaml(std::string(ELO_SOURCE_DIR) + "/config/hdl64.yaml", config);
  config.runtime.threads = 2;
  const std::vector<Eigen::Isometry3d> expected = runInProcess(config, sequence, clouds.size());
  double largest_difference = 0.0;
  for (size_t i = 0; i < odometry.size(); ++i) {
    largest_difference = std::max(largest_difference, poseDifference(poseOf(odometry[i]), expected[i]));
  }
  EXPECT_LT(largest_difference, 1e-9) << "the node's trajectory differs from elo::Odometry's";

  // ~save_trajectory writes the poses it published, in either format.
  const std::string kitti_file = kData + "/real_scans_trajectory.txt";
  node.setParam("elo_odometry/trajectory_file", kitti_file);
  std_srvs::Trigger::Response saved = callTrigger("elo_odometry/save_trajectory");
  ASSERT_TRUE(saved.success) << saved.message;
  const std::vector<Eigen::Isometry3d> written = elo::readKittiPoses(kitti_file);
  ASSERT_EQ(written.size(), clouds.size());
  for (size_t i = 0; i < written.size(); ++i) EXPECT_LT(poseDifference(written[i], poseOf(odometry[i])), 1e-9);
  node.setParam("elo_odometry/trajectory_file", kData + "/real_scans_trajectory.tum");
  node.setParam("elo_odometry/trajectory_format", "tum");
  saved = callTrigger("elo_odometry/save_trajectory");
  ASSERT_TRUE(saved.success) << saved.message;
  std::vector<double> stamps;
  elo::readTumPoses(kData + "/real_scans_trajectory.tum", &stamps);
  ASSERT_EQ(stamps.size(), clouds.size());
  EXPECT_DOUBLE_EQ(stamps.back(), clouds.back()->header.stamp.toSec());
  node.setParam("elo_odometry/trajectory_format", "csv");
  EXPECT_FALSE(callTrigger("elo_odometry/save_trajectory").success) << "an unknown format fails, saying why";

  const std::string map_file = kData + "/real_scans_map.pcd";
  node.setParam("elo_odometry/map_file", map_file);
  const std_srvs::Trigger::Response map = callTrigger("elo_odometry/save_map");
  ASSERT_TRUE(map.success) << map.message;
  EXPECT_GT(elo::readMapPcd(map_file).size(), 50000u) << "the drive's map";
  const std::string model_file = kData + "/real_scans_model.pcd";
  node.setParam("elo_odometry/model_file", model_file);
  const std_srvs::Trigger::Response model = callTrigger("elo_odometry/save_model");
  ASSERT_TRUE(model.success) << model.message;
  EXPECT_GT(elo::readPcd(model_file).size(), 10000u);

  // ~reset: the next scans start a new trajectory at the origin, even at later stamps that would
  // otherwise be registered against the old model. Sent one at a time to measure the latency.
  ASSERT_TRUE(callTrigger("elo_odometry/reset").success);
  recorder.clear();
  constexpr size_t kReplayed = 20;
  std::vector<double> round_trips_ms;
  for (size_t i = 0; i < kReplayed; ++i) {
    auto later = boost::make_shared<sensor_msgs::PointCloud2>(*clouds[i]);
    later->header.stamp += ros::Duration(100.0);
    const ros::WallTime sent = ros::WallTime::now();
    points.publish(later);
    ASSERT_TRUE(recorder.waitFor(i + 1, 30.0)) << "no odometry for replayed scan " << i;
    round_trips_ms.push_back(1000.0 * secondsSince(sent));
  }
  const std::vector<nav_msgs::Odometry> restarted = recorder.messages();
  EXPECT_LT(poseDifference(poseOf(restarted.front()), Eigen::Isometry3d::Identity()), 1e-12);
  for (size_t i = 0; i < kReplayed; ++i) {
    EXPECT_LT(poseDifference(poseOf(restarted[i]), expected[i]), 1e-6) << "replayed scan " << i;
  }
  node.setParam("elo_odometry/trajectory_file", kitti_file);
  node.setParam("elo_odometry/trajectory_format", "kitti");
  ASSERT_TRUE(callTrigger("elo_odometry/save_trajectory").success);
  EXPECT_EQ(elo::readKittiPoses(kitti_file).size(), kReplayed) << "the trajectory restarted at the reset";

  ros::WallDuration(1.5).sleep();  // one more diagnostics window
  const std::vector<double> reported = reported_latency.windowMeans();
  std::printf("latency, scans sent one at a time: publish -> odometry received %.1f ms mean, %.1f ms max; "
              "node-reported (received -> published) %.1f ms in its last window\n",
              std::accumulate(round_trips_ms.begin(), round_trips_ms.end(), 0.0) / round_trips_ms.size(),
              *std::max_element(round_trips_ms.begin(), round_trips_ms.end()),
              reported.empty() ? 0.0 : reported.back());
}

}  // namespace
