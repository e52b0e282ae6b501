// rostest (fault_cases.test): the nodelet in a manager, fed the clouds of the simulated bag with faults
// between them: an empty cloud, a cloud of NaNs, a repeated stamp, a blocked sensor and the bag played
// again. Every cloud ends up as odometry or in a counter of the diagnostics under its reason, the bag
// loop restarts the odometry with a warning, and the scans after the faults are tracked as before.
// Nodelets with an impossible parameter refuse to start and name it, and the manager carries on.
#include <diagnostic_msgs/DiagnosticArray.h>
#include <nodelet/NodeletList.h>
#include <nodelet/NodeletLoad.h>
#include <rosgraph_msgs/Log.h>

#include <boost/make_shared.hpp>

#include <algorithm>
#include <cstring>
#include <limits>
#include <map>
#include <optional>

#include "elo/io/config_yaml.hpp"
#include "rostest_helpers.hpp"

namespace {

using namespace elo_ros_test;

const std::string kData = ELO_ROS_TEST_DATA;

// What the nodes say on /rosout, for the warnings and errors the tests expect.
class RosoutRecorder {
 public:
  explicit RosoutRecorder(ros::NodeHandle& node)
      : subscriber_(node.subscribe("/rosout", 1000, &RosoutRecorder::onLog, this)) {}

  // Waits until the manager's messages can reach us.
  void waitForPublishers(size_t count, double timeout_seconds) {
    const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(timeout_seconds);
    while (subscriber_.getNumPublishers() < count && ros::WallTime::now() < deadline) ros::WallDuration(0.05).sleep();
  }

  // The first message at `level` containing every one of `parts`, waiting up to `timeout_seconds`.
  std::optional<std::string> find(uint8_t level, const std::vector<std::string>& parts, double timeout_seconds) {
    const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(timeout_seconds);
    do {
      {
        std::lock_guard<std::mutex> lock(mutex_);
        for (const rosgraph_msgs::Log& log : logs_) {
          if (log.level == level && containsAll(log.msg, parts)) return log.msg;
        }
      }
      ros::WallDuration(0.05).sleep();
    } while (ros::WallTime::now() < deadline);
    return std::nullopt;
  }

 private:
  static bool containsAll(const std::string& text, const std::vector<std::string>& parts) {
    return std::all_of(parts.begin(), parts.end(),
                       [&](const std::string& part) { return text.find(part) != std::string::npos; });
  }

  void onLog(const rosgraph_msgs::Log& log) {
    std::lock_guard<std::mutex> lock(mutex_);
    logs_.push_back(log);
  }

  ros::Subscriber subscriber_;
  std::mutex mutex_;
  std::vector<rosgraph_msgs::Log> logs_;
};

// The nodelet's diagnostics as key -> value, from its latest report.
class DiagnosticsRecorder {
 public:
  explicit DiagnosticsRecorder(ros::NodeHandle& node)
      : subscriber_(node.subscribe("/diagnostics", 100, &DiagnosticsRecorder::onDiagnostics, this)) {}

  // The first report whose `key` reads `value`, waiting up to `timeout_seconds`; empty on timeout.
  std::map<std::string, std::string> waitFor(const std::string& key, const std::string& value, double timeout_seconds) {
    const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(timeout_seconds);
    while (ros::WallTime::now() < deadline) {
      {
        std::lock_guard<std::mutex> lock(mutex_);
        const auto found = latest_.find(key);
        if (found != latest_.end() && found->second == value) return latest_;
      }
      ros::WallDuration(0.1).sleep();
    }
    return {};
  }

 private:
  void onDiagnostics(const diagnostic_msgs::DiagnosticArray& array) {
    for (const auto& status : array.status) {
      if (status.name.find("elo_odometry") == std::string::npos) continue;
      std::lock_guard<std::mutex> lock(mutex_);
      latest_.clear();
      for (const auto& entry : status.values) latest_[entry.key] = entry.value;
    }
  }

  ros::Subscriber subscriber_;
  std::mutex mutex_;
  std::map<std::string, std::string> latest_;
};

using CloudPtr = sensor_msgs::PointCloud2ConstPtr;

CloudPtr emptyCloud(const CloudPtr& like, const ros::Time& stamp) {
  auto cloud = boost::make_shared<sensor_msgs::PointCloud2>(*like);
  cloud->header.stamp = stamp;
  cloud->width = 0;
  cloud->row_step = 0;
  cloud->data.clear();
  return cloud;
}

// Every coordinate NaN, as a driver reports a scan without a single return.
CloudPtr nanCloud(const CloudPtr& like, const ros::Time& stamp) {
  auto cloud = boost::make_shared<sensor_msgs::PointCloud2>(*like);
  cloud->header.stamp = stamp;
  const float nan = std::numeric_limits<float>::quiet_NaN();
  for (size_t point = 0; point < cloud->width; ++point) {
    for (const auto& field : cloud->fields) {
      if (field.name == "x" || field.name == "y" || field.name == "z") {
        std::memcpy(cloud->data.data() + point * cloud->point_step + field.offset, &nan, sizeof(float));
      }
    }
  }
  return cloud;
}

// A blocked sensor: the scan at its stamp, with only its first `points` returns.
CloudPtr blockedCloud(const CloudPtr& scan, uint32_t points) {
  auto cloud = boost::make_shared<sensor_msgs::PointCloud2>(*scan);
  cloud->width = points;
  cloud->row_step = points * cloud->point_step;
  cloud->data.resize(cloud->row_step);
  return cloud;
}

// The sequence of clouds the nodelet gets, and what it must make of each.
struct Feed {
  std::vector<CloudPtr> clouds;
  std::vector<size_t> processed_scans;  // bag index of each cloud that must give odometry, in order
};

Feed faultyFeed(const CloudMessages& bag) {
  Feed feed;
  const auto scan = [&](size_t index) {
    feed.clouds.push_back(bag[index]);
    feed.processed_scans.push_back(index);
  };
  for (size_t i = 0; i < 10; ++i) scan(i);
  const ros::Duration half_period(0.05);
  feed.clouds.push_back(emptyCloud(bag[9], bag[9]->header.stamp + half_period));  // rejected: no points
  feed.clouds.push_back(nanCloud(bag[10], bag[10]->header.stamp));                // rejected: no finite points
  feed.clouds.push_back(bag[9]);                                                  // skipped: duplicate stamp
  for (size_t i = 10; i < 13; ++i) feed.clouds.push_back(blockedCloud(bag[i], 40));  // skipped: too few points
  for (size_t i = 13; i < 20; ++i) scan(i);
  for (size_t i = 0; i < 5; ++i) scan(i);  // the bag played again: time goes backwards
  return feed;
}

TEST(NodeletFaults, EveryCloudIsTrackedOrCountedWithItsReason) {
  const std::string bag = kData + "/sim.bag";
  ASSERT_TRUE(std::filesystem::exists(bag)) << bag << " is made by the ctest fixture ros_make_sim_bag";
  const CloudMessages clouds = readClouds(bag, "/points");
  const elo::Sequence sequence(kData + "/sim_sequence");
  ASSERT_GE(clouds.size(), 20u);
  const Feed feed = faultyFeed(clouds);

  ros::NodeHandle node;
  ros::Publisher points = node.advertise<sensor_msgs::PointCloud2>("points", feed.clouds.size());
  OdometryRecorder recorder(node, "odom");
  RosoutRecorder rosout(node);
  DiagnosticsRecorder diagnostics(node);
  ASSERT_TRUE(waitForConnections(points, recorder, 30.0)) << "the nodelet never connected";
  rosout.waitForPublishers(2, 10.0);

  for (const CloudPtr& cloud : feed.clouds) points.publish(cloud);
  ASSERT_TRUE(recorder.waitFor(feed.processed_scans.size(), 90.0))
      << "got " << recorder.messages().size() << " odometry messages";
  ros::WallDuration(0.5).sleep();  // room for a message too many to show up
  const std::vector<nav_msgs::Odometry> odometry = recorder.messages();
  ASSERT_EQ(odometry.size(), feed.processed_scans.size()) << "odometry for the usable scans only";

  // The first pass, faults included, is the odometry of the good scans alone; the second pass
  // restarts at the origin and repeats it.
  elo::Config config;
  elo::loadConfigYaml(std::string(ELO_SOURCE_DIR) + "/config/hdl64.yaml", config);
  config.runtime.threads = 2;
  const std::vector<Eigen::Isometry3d> expected = runInProcess(config, sequence, clouds.size());
  const size_t first_pass = feed.processed_scans.size() - 5;
  for (size_t i = 0; i < odometry.size(); ++i) {
    const size_t scan = feed.processed_scans[i];
    EXPECT_EQ(odometry[i].header.stamp, clouds[scan]->header.stamp) << "odometry " << i;
    if (i < 10 || i >= first_pass) {
      EXPECT_LT(poseDifference(poseOf(odometry[i]), expected[scan]), 1e-9) << "scan " << scan;
    }
  }
  // After the blocked scans the motion prior spans 0.4 s: still on the true track.
  const double distance = sequence.groundTruth()[19].translation().norm();
  const Eigen::Isometry3d after_faults = poseOf(odometry[first_pass - 1]);
  EXPECT_LT((after_faults.translation() - sequence.groundTruth()[19].translation()).norm(), 0.02 * distance + 0.02)
      << "scan 19 after the faults, " << distance << " m from the start";
  EXPECT_LT(poseDifference(poseOf(odometry[first_pass]), Eigen::Isometry3d::Identity()), 1e-12)
      << "the replayed bag starts again at the origin";

  EXPECT_TRUE(rosout.find(rosgraph_msgs::Log::WARN, {"time went backwards", "restarted"}, 5.0))
      << "the bag loop restarts with a warning";
  EXPECT_TRUE(rosout.find(rosgraph_msgs::Log::WARN, {"cloud ignored", "no points"}, 5.0));
  EXPECT_TRUE(rosout.find(rosgraph_msgs::Log::WARN, {"scan skipped", "duplicate stamp"}, 5.0));

  // Every cloud in exactly one counter.
  const auto report = diagnostics.waitFor("clouds received", std::to_string(feed.clouds.size()), 10.0);
  ASSERT_FALSE(report.empty()) << "no diagnostics counting " << feed.clouds.size() << " clouds";
  const auto count = [&report](const std::string& key) {
    const auto found = report.find(key);
    return found == report.end() ? std::string("<missing>") : found->second;
  };
  EXPECT_EQ(count("scans processed"), std::to_string(feed.processed_scans.size()));
  EXPECT_EQ(count("clouds rejected: no points"), "1");
  EXPECT_EQ(count("clouds rejected: no finite points"), "1");
  EXPECT_EQ(count("scans skipped: duplicate stamp"), "1");
  EXPECT_EQ(count("scans skipped: too few valid points"), "3");
  EXPECT_EQ(count("scans dropped"), "0");
  EXPECT_EQ(count("odometry restarts: time went backwards"), "1");
}

// Loads one more nodelet into the running manager, as `nodelet load` does; false when it refused (the
// manager then fails the service call).
bool loadNodelet(const std::string& name) {
  nodelet::NodeletLoad load;
  load.request.name = name;
  load.request.type = "elo_odometry/OdometryNodelet";
  EXPECT_TRUE(ros::service::waitForService("elo_manager/load_nodelet", ros::Duration(10.0)));
  return ros::service::call("elo_manager/load_nodelet", load) && load.response.success;
}

TEST(NodeletFaults, ImpossibleParametersRefuseToStartNamingThemAndTheManagerCarriesOn) {
  ros::NodeHandle node;
  RosoutRecorder rosout(node);
  rosout.waitForPublishers(2, 10.0);
  // A core parameter that cannot work, one of the wrong type, and a node setting of the wrong type.
  node.setParam("bad_width/sensor/image_width", 0);
  node.setParam("bad_slope/ground/max_slope_deg", std::string("steep"));
  node.setParam("bad_path/path_length", std::string("long"));
  const std::vector<std::pair<std::string, std::string>> nodelets = {
      {"bad_width", "sensor.image_width"}, {"bad_slope", "~ground/max_slope_deg"}, {"bad_path", "~path_length"}};
  for (const auto& [name, parameter] : nodelets) {
    EXPECT_FALSE(loadNodelet(node.resolveName(name))) << name << " started";
    EXPECT_TRUE(rosout.find(rosgraph_msgs::Log::FATAL, {"cannot start", parameter}, 5.0))
        << name << ": no fatal message naming " << parameter;
  }

  nodelet::NodeletList list;
  ASSERT_TRUE(ros::service::call("elo_manager/list", list));
  EXPECT_EQ(list.response.nodelets, std::vector<std::string>{node.resolveName("elo_odometry")})
      << "only the good nodelet runs, in a manager that survived";
}

}  // namespace
