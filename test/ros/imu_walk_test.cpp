// rostest (imu_walk.test): the IMU end to end (docs/imu.md). A VLP-16 carried by hand and swung at up to
// 188 deg/s (elo_sim --gait walk), its sweeps taken while it turns, with a consumer IMU mounted upside down
// and turned a quarter: the nodelet, fed the clouds and the Imu messages in time order at the drive's pace
// and the mount on /tf_static, tracks the walk (the LiDAR alone loses it: 173 deg of heading error on these
// scans with elo_run), and its diagnostics show the IMU's rate and no scan on the LiDAR-only prior. The
// node with the IMU on and no Imu message still gives every scan a pose, each counted as fallen back, and
// its diagnostics warn; so does the node whose IMU's mount TF does not have, counting the samples unused.
#include <diagnostic_msgs/DiagnosticArray.h>
#include <sensor_msgs/Imu.h>
#include <tf2_msgs/TFMessage.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <optional>

#include "rostest_helpers.hpp"

namespace {

using namespace elo_ros_test;

const std::string kData = ELO_ROS_TEST_DATA;
constexpr double kSweep = 0.1;       // s: the VLP-16's at 10 Hz
constexpr double kImuPeriod = 0.005;  // s: elo_sim's IMU at 200 Hz

template <typename Message>
std::vector<Message> readAll(const std::string& bag_path, const std::string& topic) {
  rosbag::Bag bag(bag_path, rosbag::bagmode::Read);
  std::vector<Message> messages;
  for (const rosbag::MessageInstance& instance : rosbag::View(bag, rosbag::TopicQuery(topic))) {
    messages.push_back(*instance.instantiate<Message>());
  }
  return messages;
}

// Every status whose name starts with `node` (the diagnostics of one node) and ends with ": imu".
class ImuDiagnostics {
 public:
  ImuDiagnostics(ros::NodeHandle& node, std::string prefix)
      : prefix_(std::move(prefix)), subscriber_(node.subscribe("/diagnostics", 100, &ImuDiagnostics::onArray, this)) {}

  std::vector<diagnostic_msgs::DiagnosticStatus> statuses() {
    std::lock_guard<std::mutex> lock(mutex_);
    return statuses_;
  }

  // The first status after the `after` first ones that `wanted` accepts, waiting for it up to the timeout:
  // the node reports once a second on a wall timer, which a loaded machine runs late.
  template <typename Predicate>
  std::optional<diagnostic_msgs::DiagnosticStatus> waitFor(size_t after, Predicate wanted, double timeout_seconds) {
    const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(timeout_seconds);
    for (;;) {
      {
        std::lock_guard<std::mutex> lock(mutex_);
        for (size_t i = after; i < statuses_.size(); ++i) {
          if (wanted(statuses_[i])) return statuses_[i];
        }
      }
      if (ros::WallTime::now() > deadline) return std::nullopt;
      ros::WallDuration(0.05).sleep();
    }
  }

 private:
  void onArray(const diagnostic_msgs::DiagnosticArray& array) {
    std::lock_guard<std::mutex> lock(mutex_);
    for (const auto& status : array.status) {
      const std::string& name = status.name;
      if (name.rfind(prefix_, 0) == 0 && name.size() > 5 && name.substr(name.size() - 5) == ": imu") {
        statuses_.push_back(status);
      }
    }
  }

  std::string prefix_;
  ros::Subscriber subscriber_;
  std::mutex mutex_;
  std::vector<diagnostic_msgs::DiagnosticStatus> statuses_;
};

std::string valueOf(const diagnostic_msgs::DiagnosticStatus& status, const std::string& key) {
  for (const auto& entry : status.values) {
    if (entry.key == key) return entry.value;
  }
  return "<missing>";
}

// Its values, a line each, for a failure's message.
std::string describe(const diagnostic_msgs::DiagnosticStatus& status) {
  std::string text;
  for (const auto& entry : status.values) text += "\n  " + entry.key + ": " + entry.value;
  return text;
}

double rotationDeg(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b) {
  return Eigen::AngleAxisd(a.linear().transpose() * b.linear()).angle() * 180.0 / M_PI;
}

bool waitForSubscribers(const ros::Publisher& publisher, double timeout_seconds) {
  const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(timeout_seconds);
  while (publisher.getNumSubscribers() == 0 && ros::WallTime::now() < deadline) ros::WallDuration(0.05).sleep();
  return publisher.getNumSubscribers() > 0;
}

class ImuWalk : public ::testing::Test {
 protected:
  void SetUp() override {
    const std::string bag = kData + "/imu_walk.bag";
    ASSERT_TRUE(std::filesystem::exists(bag)) << bag << " is made by the ctest fixture ros_make_imu_walk_bag";
    clouds = readClouds(bag, "/points");
    imu = readAll<sensor_msgs::Imu>(bag, "/imu");
    mount = readAll<tf2_msgs::TFMessage>(bag, "/tf_static");
    truth = readAll<nav_msgs::Odometry>(bag, "/ground_truth");
  }

  // As a driver and an IMU publish them: each cloud once the samples up to its sweep's end and the next
  // are out (the stamps are mid-sweep: azimuth times), at the drive's pace; the first `scans` of them.
  // Returns how many samples went out before the last cloud.
  size_t play(size_t scans, ros::Publisher& imu_topic, const std::vector<ros::Publisher*>& cloud_topics) {
    size_t next = 0;
    for (size_t i = 0; i < scans; ++i) {
      const ros::Time sweep_end = clouds[i]->header.stamp + ros::Duration(kSweep / 2 + kImuPeriod);
      for (; next < imu.size() && imu[next].header.stamp <= sweep_end; ++next) imu_topic.publish(imu[next]);
      for (ros::Publisher* topic : cloud_topics) topic->publish(clouds[i]);
      ros::WallDuration(kSweep).sleep();
    }
    return next;
  }

  CloudMessages clouds;
  std::vector<sensor_msgs::Imu> imu;
  std::vector<tf2_msgs::TFMessage> mount;
  std::vector<nav_msgs::Odometry> truth;
};

TEST_F(ImuWalk, TheNodeletTracksTheSwungWalkAndTheNodeWithoutImuMessagesWarns) {
  ASSERT_EQ(truth.size(), clouds.size());
  ASSERT_GT(imu.size(), 150 * clouds.size() / 10) << "elo_sim's IMU samples at 200 Hz";
  ASSERT_EQ(mount.size(), 1u) << "elo_sim's bag holds the IMU's mount on /tf_static";
  ASSERT_EQ(mount.front().transforms.front().child_frame_id, imu.front().header.frame_id);

  ros::NodeHandle node;
  ros::Publisher walk_points = node.advertise<sensor_msgs::PointCloud2>("/walk/points", clouds.size());
  ros::Publisher walk_imu = node.advertise<sensor_msgs::Imu>("/walk/imu", imu.size());
  ros::Publisher silent_points = node.advertise<sensor_msgs::PointCloud2>("/silent/points", clouds.size());
  ros::Publisher tf_static = node.advertise<tf2_msgs::TFMessage>("/tf_static", 1, true);
  OdometryRecorder walk(node, "/walk/odom");
  OdometryRecorder silent(node, "/silent/odom");
  ImuDiagnostics walk_diagnostics(node, "walk/");
  ImuDiagnostics silent_diagnostics(node, "silent/");
  tf_static.publish(mount.front());
  ASSERT_TRUE(waitForConnections(walk_points, walk, 30.0)) << "the nodelet never connected";
  ASSERT_TRUE(waitForConnections(silent_points, silent, 30.0)) << "the node never connected";
  ASSERT_TRUE(waitForSubscribers(walk_imu, 10.0)) << "the nodelet does not listen to its imu topic";

  // The core's counts in the diagnostics are as of the last scan: the samples after it go out once the
  // last scan has its pose (a slow machine, or a sanitizer build, processes it well after it was sent).
  const size_t before_last_scan = play(clouds.size(), walk_imu, {&walk_points, &silent_points});
  ASSERT_TRUE(walk.waitFor(clouds.size(), 90.0)) << "got " << walk.messages().size() << " odometry messages";
  ASSERT_TRUE(silent.waitFor(clouds.size(), 90.0)) << "got " << silent.messages().size() << " odometry messages";
  const size_t reported_during_walk = walk_diagnostics.statuses().size();
  for (size_t next = before_last_scan; next < imu.size(); ++next) walk_imu.publish(imu[next]);
  // The walk over: a status that has every message and then a second without one.
  const std::string all_received = std::to_string(imu.size());
  const auto walk_last = walk_diagnostics.waitFor(
      reported_during_walk,
      [&](const auto& status) {
        return valueOf(status, "Imu messages received") == all_received && status.message.find("IMU silent") != std::string::npos;
      },
      10.0);

  const std::vector<nav_msgs::Odometry> tracked = walk.messages();
  ASSERT_EQ(tracked.size(), clouds.size());
  double position_error = 0.0;
  double rotation_error = 0.0;
  for (size_t i = 0; i < tracked.size(); ++i) {
    position_error = std::max(position_error, (poseOf(tracked[i]).translation() - poseOf(truth[i]).translation()).norm());
    rotation_error = std::max(rotation_error, rotationDeg(poseOf(tracked[i]), poseOf(truth[i])));
  }
  std::printf("[ imu walk ] nodelet with the IMU over %zu scans (%.1f m): largest error %.3f m, %.2f deg\n",
              tracked.size(), poseOf(truth.back()).translation().norm(), position_error, rotation_error);
  EXPECT_LT(position_error, 0.25);
  EXPECT_LT(rotation_error, 2.5);

  const auto walk_statuses = walk_diagnostics.statuses();
  ASSERT_FALSE(walk_statuses.empty()) << "no imu status from the nodelet";
  const bool rate_seen = std::any_of(walk_statuses.begin(), walk_statuses.end(), [](const auto& status) {
    const double rate = std::stod(valueOf(status, "IMU rate (Hz)"));
    return status.level == diagnostic_msgs::DiagnosticStatus::OK && rate > 150.0 && rate < 250.0;
  });
  EXPECT_TRUE(rate_seen) << "no OK status at 200 Hz during the walk; the last: " << walk_statuses.back().message;
  ASSERT_TRUE(walk_last) << "no status with all " << all_received << " Imu messages and the IMU silent since; the last: "
                         << walk_statuses.back().message << describe(walk_statuses.back());
  EXPECT_EQ(valueOf(*walk_last, "scans on the LiDAR-only prior"), "0") << describe(*walk_last);
  // The last scan waits for the first sample at or past its sweep's end: the one after it, sent with the
  // scan, may reach the nodelet after the scan's counts were taken.
  const double last_sweep_end = (clouds.back()->header.stamp + ros::Duration(kSweep / 2)).toSec() - 1e-6;
  const size_t needed = 1 + std::count_if(imu.begin(), imu.end(), [&](const sensor_msgs::Imu& sample) {
                          return sample.header.stamp.toSec() < last_sweep_end;
                        });
  const size_t taken = std::stoul(valueOf(*walk_last, "IMU samples taken"));
  EXPECT_GE(taken, needed) << describe(*walk_last);
  EXPECT_LE(taken, before_last_scan) << describe(*walk_last);
  EXPECT_NE(valueOf(*walk_last, "gyro bias (deg/s)"), "<missing>");
  // The 4 s walk is shorter than the ten seconds the tilt against gravity is measured over.
  EXPECT_EQ(valueOf(*walk_last, "tilt against gravity (deg)"), "not measured yet") << describe(*walk_last);
  EXPECT_EQ(valueOf(*walk_last, "scans held to gravity"), "0");

  EXPECT_EQ(silent.messages().size(), clouds.size()) << "every scan gets a pose without the IMU";
  const std::string every_scan = std::to_string(clouds.size());
  const auto silent_last = silent_diagnostics.waitFor(
      0, [&](const auto& status) { return valueOf(status, "scans on the LiDAR-only prior") == every_scan; }, 10.0);
  const auto silent_statuses = silent_diagnostics.statuses();
  ASSERT_FALSE(silent_statuses.empty()) << "no imu status from the node";
  for (const auto& status : silent_statuses) {
    EXPECT_EQ(status.level, diagnostic_msgs::DiagnosticStatus::WARN) << status.message;
    EXPECT_NE(status.message.find("IMU silent"), std::string::npos) << status.message;
  }
  ASSERT_TRUE(silent_last) << "no status with every scan on the LiDAR-only prior; the last:" << describe(silent_statuses.back());
  EXPECT_EQ(valueOf(*silent_last, "scans on the LiDAR-only prior: no IMU samples over the scan"), every_scan);
  EXPECT_EQ(valueOf(*silent_last, "Imu messages received"), "0");
}

// TF has no transform from the Imu messages' frame to the clouds': the node warns, leaves the samples
// unused (counted, as they age out of the second it holds while it looks) and every scan on the LiDAR-only
// prior, with a pose.
TEST_F(ImuWalk, WithoutTheMountInTfTheSamplesAreUnusedAndEveryScanFallsBack) {
  constexpr size_t kScans = 20;
  ros::NodeHandle node;
  ros::Publisher points = node.advertise<sensor_msgs::PointCloud2>("/untransformed/points", kScans);
  ros::Publisher imu_topic = node.advertise<sensor_msgs::Imu>("/untransformed/imu", imu.size());
  OdometryRecorder recorder(node, "/untransformed/odom");
  ImuDiagnostics diagnostics(node, "untransformed/");
  for (sensor_msgs::Imu& message : imu) message.header.frame_id = "imu_nowhere";
  ASSERT_TRUE(waitForConnections(points, recorder, 30.0)) << "the node never connected";
  ASSERT_TRUE(waitForSubscribers(imu_topic, 10.0)) << "the node does not listen to its imu topic";
  play(kScans, imu_topic, {&points});
  ASSERT_TRUE(recorder.waitFor(kScans, 60.0)) << "got " << recorder.messages().size() << " odometry messages";
  const std::string every_scan = std::to_string(kScans);
  const auto last = diagnostics.waitFor(
      0, [&](const auto& status) { return valueOf(status, "scans on the LiDAR-only prior") == every_scan; }, 10.0);
  const auto statuses = diagnostics.statuses();
  ASSERT_FALSE(statuses.empty()) << "no imu status from the node";
  ASSERT_TRUE(last) << "no status with every scan on the LiDAR-only prior; the last:" << describe(statuses.back());
  EXPECT_EQ(last->level, diagnostic_msgs::DiagnosticStatus::WARN) << last->message;
  EXPECT_EQ(valueOf(*last, "IMU samples taken"), "0");
  const std::string unused = valueOf(*last, "Imu messages unused: no IMU -> LiDAR transform from TF");
  ASSERT_NE(unused, "<missing>");
  EXPECT_GT(std::stoul(unused), 100u) << "a 200 Hz IMU over 2 s, its last second held";
}

}  // namespace
