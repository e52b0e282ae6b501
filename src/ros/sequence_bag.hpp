// Writes scans as a ROS bag of sensor_msgs/PointCloud2 at their stamps, with the ground truth as
// nav_msgs/Odometry on /ground_truth and TF, and IMU samples as sensor_msgs/Imu with the IMU's mount on
// /tf_static. kitti_to_bag (scans read from disk) and elo_sim --bag (scans straight from the simulator,
// ring and per-point time included, and its IMU) both use it.
#pragma once

#include <rosbag/bag.h>

#include <Eigen/Geometry>
#include <string>

#include "elo/imu/imu_track.hpp"
#include "elo/types.hpp"

namespace elo_ros {

struct SequenceBagOptions {
  std::string topic = "/points";
  std::string frame = "velodyne";  // the clouds' frame_id
  double start_time = 1.0;         // added to every scan time: ROS reads time 0 as 'no time'
  std::string gt_frame = "odom";   // parent frame of the ground truth
  std::string gt_child_frame;      // empty: <frame>_ground_truth
  std::string imu_topic = "/imu";
  std::string imu_frame = "imu";
  // s after its stamp at which a cloud is recorded (played back): 0, or when a driver would publish it,
  // once its sweep and the IMU samples that cover it are out. Its header stamp is the scan's.
  double cloud_record_delay = 0.0;
};

class SequenceBagWriter {
 public:
  // Throws rosbag::BagException when the bag cannot be opened for writing.
  SequenceBagWriter(const std::string& path, const SequenceBagOptions& options);

  void write(const elo::PointCloud& cloud);
  // `ground_truth`: the sensor's pose in the frame of the first scan.
  void write(const elo::PointCloud& cloud, const Eigen::Isometry3d& ground_truth);
  // An IMU sample (stamped as the scans) on imu_topic, in imu_frame, recorded at its stamp.
  void write(const elo::ImuSample& sample);
  // `lidar_from_imu` (the IMU's mount in the clouds' frame) as the static transform frame -> imu_frame on
  // /tf_static, stamped and recorded at `stamp` (as the scans, before the first sample).
  void writeImuMount(const Eigen::Isometry3d& lidar_from_imu, double stamp);
  void close() { bag_.close(); }

  size_t scans() const { return scans_; }
  size_t points() const { return points_; }

 private:
  ros::Time writeCloud(const elo::PointCloud& cloud);
  void writeGroundTruth(const ros::Time& stamp, const Eigen::Isometry3d& pose);

  SequenceBagOptions options_;
  rosbag::Bag bag_;
  size_t scans_ = 0;
  size_t points_ = 0;
};

}  // namespace elo_ros
