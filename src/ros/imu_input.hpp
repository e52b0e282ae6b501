// The node's IMU (imu.enabled, docs/imu.md): sensor_msgs/Imu on `imu` handed to the drive session, the
// IMU's mount from TF (~imu_mount_from_tf) or from imu.position and imu.rotation_deg, and each scan
// waiting (at most ~imu_max_wait) for the samples that cover its sweep.
#pragma once

#include <ros/ros.h>
#include <sensor_msgs/Imu.h>
#include <tf2_ros/buffer.h>
#include <tf2_ros/transform_listener.h>

#include <chrono>
#include <condition_variable>
#include <deque>
#include <memory>
#include <mutex>
#include <string>

#include "diagnostics.hpp"
#include "elo/drive_session.hpp"
#include "parameters.hpp"

namespace elo_ros {

// Why the node did not hand a message to the odometry (ImuStatistics::messageUnused()), besides
// imu_conversion.hpp's.
namespace imu_message {
inline constexpr char kNoMount[] = "no IMU -> LiDAR transform from TF";
}  // namespace imu_message

class ImuInput {
 public:
  // Subscribes to `imu` on `node`. `name`: the nodelet's, which its messages are logged under.
  ImuInput(ros::NodeHandle& node, const NodeSettings& settings, elo::DriveSession& session, std::string name);

  // On the scans' thread, before the scan stamped `stamp` (s) in `sensor_frame` is processed: a wait, at
  // the first scan and while the IMU is heard from, for a sample at or after the sweep's end; then, with
  // ~imu_mount_from_tf, the mount while it is unknown (looked up once with ~tf_timeout, then at each scan
  // without waiting).
  void beforeScan(const std::string& sensor_frame, double stamp);
  // After it: the core's IMU state into the statistics.
  void afterScan() { statistics_.update(session_.imuStatus()); }

  ImuStatistics& statistics() { return statistics_; }

 private:
  using Clock = std::chrono::steady_clock;

  void onImu(const sensor_msgs::ImuConstPtr& message);
  // On the scans' thread: the mount from TF, handed to the session with the samples held for it; a
  // throttled warning while TF does not have it.
  void lookUpMount(const std::string& sensor_frame);
  // Under mutex_: to the session, or held while the mount is looked for (the last second of them; older
  // ones are counted as unused).
  void take(const elo::ImuSample& sample);

  const NodeSettings& settings_;
  elo::DriveSession& session_;
  std::string name_;
  double sweep_end_;    // s from a scan's stamp to the end of its sweep
  double time_offset_;  // imu.time_offset
  ImuStatistics statistics_;

  std::mutex mutex_;
  std::condition_variable sample_arrived_;
  bool mount_known_;          // written on the scans' thread, under mutex_
  bool mount_tried_ = false;  // the scans' thread's
  std::string imu_frame_;             // of the first message
  std::deque<elo::ImuSample> held_;   // while the mount is looked for
  bool first_scan_ = true;
  double latest_stamp_ = -1e300;      // of the latest sample received, on the scans' clock
  Clock::time_point latest_arrival_;  // of the last message

  std::unique_ptr<tf2_ros::Buffer> tf_buffer_;
  std::unique_ptr<tf2_ros::TransformListener> tf_listener_;
  ros::Subscriber subscriber_;
};

}  // namespace elo_ros
