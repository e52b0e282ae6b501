#include "sequence_bag.hpp"

#include <nav_msgs/Odometry.h>
#include <tf2_eigen/tf2_eigen.h>
#include <tf2_msgs/TFMessage.h>

#include "cloud_conversion.hpp"
#include "imu_conversion.hpp"

namespace elo_ros {

SequenceBagWriter::SequenceBagWriter(const std::string& path, const SequenceBagOptions& options)
    : options_(options), bag_(path, rosbag::bagmode::Write) {
  if (options_.gt_child_frame.empty()) options_.gt_child_frame = options_.frame + "_ground_truth";
}

void SequenceBagWriter::write(const elo::PointCloud& cloud) { writeCloud(cloud); }

void SequenceBagWriter::write(const elo::PointCloud& cloud, const Eigen::Isometry3d& ground_truth) {
  writeGroundTruth(writeCloud(cloud), ground_truth);
}

ros::Time SequenceBagWriter::writeCloud(const elo::PointCloud& cloud) {
  sensor_msgs::PointCloud2 message = toPointCloud2(cloud, options_.frame);
  message.header.stamp = ros::Time(cloud.stamp + options_.start_time);
  bag_.write(options_.topic, message.header.stamp + ros::Duration(options_.cloud_record_delay), message);
  ++scans_;
  points_ += cloud.size();
  return message.header.stamp;
}

void SequenceBagWriter::write(const elo::ImuSample& sample) {
  elo::ImuSample shifted = sample;
  shifted.stamp += options_.start_time;
  const sensor_msgs::Imu message = imuMessageOf(shifted, options_.imu_frame);
  bag_.write(options_.imu_topic, message.header.stamp, message);
}

void SequenceBagWriter::writeImuMount(const Eigen::Isometry3d& lidar_from_imu, double stamp) {
  geometry_msgs::TransformStamped transform = tf2::eigenToTransform(lidar_from_imu);
  transform.header.stamp = ros::Time(stamp + options_.start_time);
  transform.header.frame_id = options_.frame;
  transform.child_frame_id = options_.imu_frame;
  tf2_msgs::TFMessage tf;
  tf.transforms.push_back(transform);
  bag_.write("/tf_static", transform.header.stamp, tf);
}

void SequenceBagWriter::writeGroundTruth(const ros::Time& stamp, const Eigen::Isometry3d& pose) {
  nav_msgs::Odometry odometry;
  odometry.header.stamp = stamp;
  odometry.header.frame_id = options_.gt_frame;
  odometry.child_frame_id = options_.gt_child_frame;
  odometry.pose.pose = tf2::toMsg(pose);
  bag_.write("/ground_truth", stamp, odometry);

  geometry_msgs::TransformStamped transform = tf2::eigenToTransform(pose);
  transform.header = odometry.header;
  transform.child_frame_id = options_.gt_child_frame;
  tf2_msgs::TFMessage tf;
  tf.transforms.push_back(transform);
  bag_.write("/tf", stamp, tf);
}

}  // namespace elo_ros
