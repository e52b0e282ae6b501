// rostest (sim_bag.test): the nodelet in a manager, fed a bag that kitti_to_bag made from an elo_sim
// sequence. One odometry message per scan with the scan's stamp and REP-105 frames, a complete TF tree,
// the path, the models, the drive's map (~save_map and `map`) and diagnostics, and a trajectory identical to elo::Odometry run in-process on
// the same scans with the sequence's own stamps, as elo_run runs them; and the bag's ground truth.
#include <diagnostic_msgs/DiagnosticArray.h>
#include <nav_msgs/Path.h>
#include <tf2_ros/transform_listener.h>

#include <std_srvs/Trigger.h>

#include <atomic>
#include <fstream>
#include <iterator>

#include "elo/io/config_yaml.hpp"
#include "elo/io/map_pcd.hpp"
#include "rostest_helpers.hpp"

namespace {

using namespace elo_ros_test;

const std::string kData = ELO_ROS_TEST_DATA;

// The latest message of a topic, and how many arrived.
template <typename Message>
class LatestMessage {
 public:
  LatestMessage(ros::NodeHandle& node, const std::string& topic)
      : subscriber_(node.subscribe(topic, 10, &LatestMessage::onMessage, this)) {}

  size_t count() const { return count_; }
  // Whether a message arrives within `timeout_seconds` (at once if one has).
  bool waitForOne(double timeout_seconds) const {
    const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(timeout_seconds);
    while (count_ == 0 && ros::WallTime::now() < deadline) ros::WallDuration(0.02).sleep();
    return count_ > 0;
  }
  Message latest() {
    std::lock_guard<std::mutex> lock(mutex_);
    return latest_;
  }
  bool connected() const { return subscriber_.getNumPublishers() > 0; }

 private:
  void onMessage(const Message& message) {
    std::lock_guard<std::mutex> lock(mutex_);
    latest_ = message;
    ++count_;
  }

  ros::Subscriber subscriber_;
  std::mutex mutex_;
  Message latest_;
  std::atomic<size_t> count_{0};
};

std::vector<std::string> fieldNames(const sensor_msgs::PointCloud2& cloud) {
  std::vector<std::string> names;
  for (const auto& field : cloud.fields) names.push_back(field.name);
  return names;
}

// kitti_to_bag's ground truth: one pose per scan, at the scan's stamp, as elo_sim wrote it.
TEST(SimulatedBag, CarriesTheGroundTruth) {
  rosbag::Bag bag(kData + "/sim.bag", rosbag::bagmode::Read);
  const elo::Sequence sequence(kData + "/sim_sequence");
  const CloudMessages clouds = readClouds(kData + "/sim.bag", "/points");
  std::vector<nav_msgs::Odometry> truth;
  for (const rosbag::MessageInstance& instance : rosbag::View(bag, rosbag::TopicQuery("/ground_truth"))) {
    truth.push_back(*instance.instantiate<nav_msgs::Odometry>());
  }
  ASSERT_EQ(truth.size(), sequence.size());
  for (size_t i = 0; i < truth.size(); ++i) {
    EXPECT_EQ(truth[i].header.stamp, clouds[i]->header.stamp);
    EXPECT_LT(poseDifference(poseOf(truth[i]), sequence.groundTruth()[i]), 1e-12);
  }
  EXPECT_EQ(truth.front().header.frame_id, "odom");
  EXPECT_EQ(truth.front().child_frame_id, "velodyne_ground_truth");
}

// ~save_map after the drive: a binary PCD of the drive's map with x y z intensity and normals, in the odom
// frame (base_link on the road under the sensor at the first scan: the road lies at z = 0, where the
// sensor frame has it 1.73 m lower), covering the drive; and the latched, thinned `map` topic.
void expectTheDrivesMap(ros::NodeHandle& node, LatestMessage<sensor_msgs::PointCloud2>& map_topic, double driven) {
  const std::string map_file = kData + "/sim_bag_map.pcd";
  std::filesystem::remove(map_file);
  node.setParam("elo_odometry/map_file", map_file);
  std_srvs::Trigger trigger;
  ASSERT_TRUE(ros::service::waitForService("elo_odometry/save_map", ros::Duration(10.0)));
  ASSERT_TRUE(ros::service::call("elo_odometry/save_map", trigger));
  ASSERT_TRUE(trigger.response.success) << trigger.response.message;
  std::ifstream stream(map_file, std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(stream)), std::istreambuf_iterator<char>());
  EXPECT_NE(bytes.find("FIELDS x y z intensity normal_x normal_y normal_z\n"), std::string::npos);
  EXPECT_NE(bytes.find("DATA binary\n"), std::string::npos);
  const elo::MapCloud map = elo::readMapPcd(map_file);
  ASSERT_GT(map.size(), 40000u) << "the 3 s drive's map holds about 50,000 points";
  // The road within 10 m of the start: its height in the file's frame.
  std::vector<float> road_heights;
  size_t normals = 0;
  float farthest = 0.0f;
  for (size_t i = 0; i < map.size(); ++i) {
    const elo::Vec3f& point = map.points[i];
    if (point.head<2>().norm() < 10.0f && std::abs(point.z()) < 1.0f) road_heights.push_back(point.z());
    if (!map.normals[i].isZero()) {
      ++normals;
      EXPECT_NEAR(map.normals[i].norm(), 1.0f, 1e-4f);
    }
    farthest = std::max(farthest, point.x());
  }
  ASSERT_GT(road_heights.size(), 100u) << "no road around the start at z = 0: not the odom frame";
  std::nth_element(road_heights.begin(), road_heights.begin() + road_heights.size() / 2, road_heights.end());
  EXPECT_NEAR(road_heights[road_heights.size() / 2], 0.0f, 0.1f);
  EXPECT_GT(normals, map.size() / 10) << "normals where the pipeline has them";
  EXPECT_GT(farthest, driven) << "the map reaches beyond the last pose";

  ASSERT_TRUE(map_topic.waitForOne(5.0)) << "no `map` message";
  const sensor_msgs::PointCloud2 shown = map_topic.latest();
  EXPECT_EQ(shown.header.frame_id, "odom");
  EXPECT_EQ(fieldNames(shown), (std::vector<std::string>{"x", "y", "z", "intensity"}));
  // The 3 s drive is shorter than ~map_publish_period: the message is the map after the first scan, its
  // road (a non-ground voxel waits for three scans).
  EXPECT_GT(shown.width, 5000u);
}

TEST(SimulatedBag, NodeletInManagerMatchesTheCoreInProcess) {
  const std::string bag = kData + "/sim.bag";
  ASSERT_TRUE(std::filesystem::exists(bag)) << bag << " is made by the ctest fixture ros_make_sim_bag";
  const CloudMessages clouds = readClouds(bag, "/points");
  const elo::Sequence sequence(kData + "/sim_sequence");
  ASSERT_EQ(clouds.size(), sequence.size());

  ros::NodeHandle node;
  ros::Publisher points = node.advertise<sensor_msgs::PointCloud2>("points", clouds.size());
  OdometryRecorder recorder(node, "odom");
  LatestMessage<nav_msgs::Path> path(node, "path");
  LatestMessage<sensor_msgs::PointCloud2> nonground_model(node, "model/nonground");
  LatestMessage<sensor_msgs::PointCloud2> ground_model(node, "model/ground");
  LatestMessage<diagnostic_msgs::DiagnosticArray> diagnostics(node, "/diagnostics");
  LatestMessage<sensor_msgs::PointCloud2> map_topic(node, "map");
  tf2_ros::Buffer tf_buffer;
  tf2_ros::TransformListener tf_listener(tf_buffer);

  // Models and path go out only to subscribers: every connection must stand before the first scan.
  ASSERT_TRUE(waitForConnections(points, recorder, 30.0)) << "the nodelet never connected";
  const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(10.0);
  while (!(path.connected() && nonground_model.connected() && ground_model.connected()) &&
         ros::WallTime::now() < deadline) {
    ros::WallDuration(0.05).sleep();
  }
  for (const auto& cloud : clouds) points.publish(cloud);
  ASSERT_TRUE(recorder.waitFor(clouds.size(), 90.0)) << "got " << recorder.messages().size() << " odometry messages";
  ros::WallDuration(0.5).sleep();  // room for a message too many to show up

  const std::vector<nav_msgs::Odometry> odometry = recorder.messages();
  ASSERT_EQ(odometry.size(), clouds.size()) << "one odometry message per scan";
  for (size_t i = 0; i < odometry.size(); ++i) {
    EXPECT_EQ(odometry[i].header.stamp, clouds[i]->header.stamp) << "scan " << i;
    EXPECT_EQ(odometry[i].header.frame_id, "odom");
    EXPECT_EQ(odometry[i].child_frame_id, "base_link");
  }

  const Eigen::Isometry3d base_from_sensor =
      tf2::transformToEigen(tf_buffer.lookupTransform("base_link", "velodyne", ros::Time(0), ros::Duration(5.0)));
  elo::Config config;
  elo::loadConfigYaml(std::string(ELO_SOURCE_DIR) + "/config/hdl64.yaml", config);
  config.runtime.threads = 2;
  const std::vector<Eigen::Isometry3d> expected = runInProcess(config, sequence, clouds.size());
  double largest_difference = 0.0;
  for (size_t i = 0; i < odometry.size(); ++i) {
    const Eigen::Isometry3d expected_base = base_from_sensor * expected[i] * base_from_sensor.inverse();
    largest_difference = std::max(largest_difference, poseDifference(poseOf(odometry[i]), expected_base));
  }
  EXPECT_LT(largest_difference, 1e-9) << "the nodelet's trajectory differs from elo_run's";
  // Not a test of the core's accuracy: a guard against both runs agreeing on nonsense.
  const Eigen::Vector3d true_end = sequence.groundTruth().back().translation();
  EXPECT_LT((expected.back().translation() - true_end).norm(), 0.05 * true_end.norm());

  // TF: odom -> base_link as the odometry says, and on to the sensor.
  const ros::Time last_stamp = odometry.back().header.stamp;
  const Eigen::Isometry3d odom_to_base =
      tf2::transformToEigen(tf_buffer.lookupTransform("odom", "base_link", last_stamp, ros::Duration(5.0)));
  EXPECT_LT(poseDifference(odom_to_base, poseOf(odometry.back())), 1e-9);
  EXPECT_TRUE(tf_buffer.canTransform("odom", "velodyne", last_stamp, ros::Duration(1.0)));

  const nav_msgs::Path last_path = path.latest();
  ASSERT_EQ(last_path.poses.size(), clouds.size());
  EXPECT_EQ(last_path.header.frame_id, "odom");
  EXPECT_EQ(last_path.poses.back().pose, odometry.back().pose.pose);

  ASSERT_GT(nonground_model.count(), 0u);
  ASSERT_GT(ground_model.count(), 0u);
  const sensor_msgs::PointCloud2 model = nonground_model.latest();
  EXPECT_EQ(model.header.frame_id, "velodyne");
  EXPECT_EQ(fieldNames(model), (std::vector<std::string>{"x", "y", "z", "normal_x", "normal_y", "normal_z"}));
  EXPECT_GT(model.width, 10000u);
  EXPECT_GT(ground_model.latest().width, 10000u);

  expectTheDrivesMap(node, map_topic, sequence.groundTruth().back().translation().norm());

  // The node publishes its diagnostics once a second, which the drive may take less than.
  ASSERT_TRUE(diagnostics.waitForOne(5.0)) << "no /diagnostics message";
  const auto statuses = diagnostics.latest().status;
  EXPECT_TRUE(std::any_of(statuses.begin(), statuses.end(),
                          [](const auto& status) { return status.name.find("odometry") != std::string::npos; }));
}

}  // namespace
