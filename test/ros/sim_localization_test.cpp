// rostest (sim_localization.test): the nodelet localizing the simulated bag in a map of its scans, from
// an initial pose 1.5 m and 8 degrees off given on /initialpose (rviz's 2D Pose Estimate: x, y and yaw of
// base_link in the map). One localization/pose per scan once localized, close to the ground truth; TF
// map -> odom; a "localization" diagnostics status.
#include <diagnostic_msgs/DiagnosticArray.h>
#include <geometry_msgs/PoseWithCovarianceStamped.h>
#include <std_srvs/Trigger.h>
#include <tf2_ros/transform_listener.h>

#include "rostest_helpers.hpp"

namespace {

using namespace elo_ros_test;

const std::string kData = ELO_ROS_TEST_DATA;

class PoseRecorder {
 public:
  PoseRecorder(ros::NodeHandle& node, const std::string& topic)
      : subscriber_(node.subscribe(topic, 1000, &PoseRecorder::onPose, this)) {}
  std::vector<geometry_msgs::PoseWithCovarianceStamped> poses() {
    std::lock_guard<std::mutex> lock(mutex_);
    return poses_;
  }

 private:
  void onPose(const geometry_msgs::PoseWithCovarianceStamped& pose) {
    std::lock_guard<std::mutex> lock(mutex_);
    poses_.push_back(pose);
  }
  ros::Subscriber subscriber_;
  std::mutex mutex_;
  std::vector<geometry_msgs::PoseWithCovarianceStamped> poses_;
};

TEST(SimulatedLocalization, LocalizesTheBagFromAnInitialPoseOnTheTopic) {
  const std::string bag = kData + "/sim.bag";
  ASSERT_TRUE(std::filesystem::exists(bag)) << bag << " is made by the ctest fixture ros_make_sim_bag";
  const CloudMessages clouds = readClouds(bag, "/points");
  const elo::Sequence sequence(kData + "/sim_sequence");

  ros::NodeHandle node;
  ros::Publisher points = node.advertise<sensor_msgs::PointCloud2>("points", clouds.size());
  ros::Publisher initial_pose = node.advertise<geometry_msgs::PoseWithCovarianceStamped>("/initialpose", 1);
  OdometryRecorder recorder(node, "odom");
  PoseRecorder localized(node, "localization/pose");
  tf2_ros::Buffer tf_buffer;
  tf2_ros::TransformListener tf_listener(tf_buffer);
  ASSERT_TRUE(waitForConnections(points, recorder, 30.0)) << "the nodelet never connected";
  const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(10.0);
  while (initial_pose.getNumSubscribers() == 0 && ros::WallTime::now() < deadline) ros::WallDuration(0.05).sleep();
  ASSERT_GT(initial_pose.getNumSubscribers(), 0u) << "nobody listens on /initialpose";
  const std::string relocalize = "elo_odometry/relocalize";
  ASSERT_TRUE(ros::service::waitForService(relocalize, ros::Duration(10.0))) << relocalize;
  std_srvs::Trigger before_any_pose;
  ASSERT_TRUE(ros::service::call(relocalize, before_any_pose));
  EXPECT_FALSE(before_any_pose.response.success) << "nothing to search around before a pose is given";
  EXPECT_NE(before_any_pose.response.message.find("no pose in the map yet"), std::string::npos)
      << before_any_pose.response.message;

  // base_link in the map at the first scan (the map's frame is the sensor's there), 1.5 m and 8 degrees off.
  const Eigen::Isometry3d base_from_sensor =
      tf2::transformToEigen(tf_buffer.lookupTransform("base_link", "velodyne", ros::Time(0), ros::Duration(5.0)));
  const Eigen::Isometry3d hint = sequence.groundTruth().front() * base_from_sensor.inverse() *
                                 Eigen::Translation3d(1.2, -0.9, 0.0) *
                                 Eigen::AngleAxisd(8.0 * M_PI / 180.0, Eigen::Vector3d::UnitZ());
  geometry_msgs::PoseWithCovarianceStamped estimate;
  estimate.header.frame_id = "map";
  estimate.header.stamp = ros::Time::now();
  estimate.pose.pose = tf2::toMsg(hint);
  estimate.pose.pose.position.z = 0.0;  // rviz's 2D Pose Estimate has no height
  initial_pose.publish(estimate);
  ros::WallDuration(1.0).sleep();

  for (const auto& cloud : clouds) points.publish(cloud);
  ASSERT_TRUE(recorder.waitFor(clouds.size(), 120.0)) << "got " << recorder.messages().size() << " odometry messages";
  ros::WallDuration(0.5).sleep();

  const std::vector<geometry_msgs::PoseWithCovarianceStamped> poses = localized.poses();
  ASSERT_EQ(poses.size(), clouds.size()) << "one localized pose per scan from the first";
  double worst = 0.0;
  for (size_t i = 0; i < poses.size(); ++i) {
    EXPECT_EQ(poses[i].header.frame_id, "map");
    EXPECT_EQ(poses[i].header.stamp, clouds[i]->header.stamp);
    Eigen::Isometry3d base;
    tf2::fromMsg(poses[i].pose.pose, base);
    const Eigen::Isometry3d truth = sequence.groundTruth()[i] * base_from_sensor.inverse();
    worst = std::max(worst, (base.translation() - truth.translation()).norm());
    EXPECT_GT(poses[i].pose.covariance[0], 0.0);
  }
  EXPECT_LT(worst, 0.15);
  EXPECT_TRUE(tf_buffer.canTransform("map", "base_link", poses.back().header.stamp, ros::Duration(2.0)));
  std_srvs::Trigger while_tracking;
  ASSERT_TRUE(ros::service::call(relocalize, while_tracking));
  EXPECT_TRUE(while_tracking.response.success) << while_tracking.response.message;
}

}  // namespace
