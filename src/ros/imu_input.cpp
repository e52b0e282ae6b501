#include "imu_input.hpp"

#include <tf2_eigen/tf2_eigen.h>

#include <cmath>

#include "imu_conversion.hpp"

namespace elo_ros {
namespace {

constexpr double kWarningPeriod = 5.0;  // s between repeats of one throttled warning
// s of samples held while the mount is looked for: the intervals and sweeps of the first scans.
constexpr double kHeldSeconds = 1.0;
// s (wall) since the last message beyond which a scan no longer waits for the IMU: a silent IMU must not
// delay every scan.
constexpr double kHeardWithin = 1.0;

std::vector<double> degrees(const Eigen::Vector3d& radians) {
  return {radians.x() * 180.0 / M_PI, radians.y() * 180.0 / M_PI, radians.z() * 180.0 / M_PI};
}

}  // namespace

ImuInput::ImuInput(ros::NodeHandle& node, const NodeSettings& settings, elo::DriveSession& session, std::string name)
    : settings_(settings),
      session_(session),
      name_(std::move(name)),
      sweep_end_((session.config().deskew.time_source == elo::TimeSource::field ? 1.0 : 0.5) /
                 session.config().sensor.rotation_rate_hz),
      time_offset_(session.config().imu.time_offset),
      statistics_(session.config().imu.min_rate_hz),
      mount_known_(!settings.imu_mount_from_tf) {
  if (settings.imu_mount_from_tf) {
    tf_buffer_ = std::make_unique<tf2_ros::Buffer>();
    tf_listener_ = std::make_unique<tf2_ros::TransformListener>(*tf_buffer_, node);
  }
  // Seconds of an IMU's samples: a callback hands its sample over only between two scans.
  subscriber_ = node.subscribe("imu", 1000, &ImuInput::onImu, this);
  ROS_INFO_NAMED(name_, "IMU on %s, its mount from %s", subscriber_.getTopic().c_str(),
                 settings.imu_mount_from_tf ? "TF" : "imu.position and imu.rotation_deg");
}

void ImuInput::onImu(const sensor_msgs::ImuConstPtr& message) {
  statistics_.messageReceived(message->header.stamp.toSec());
  std::string problem;
  const std::optional<elo::ImuSample> sample = imuSampleOf(*message, problem);
  if (!sample) {
    statistics_.messageUnused(problem);
    ROS_WARN_THROTTLE_NAMED(kWarningPeriod, name_, "Imu message unused: %s", problem.c_str());
    return;
  }
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (imu_frame_.empty()) imu_frame_ = message->header.frame_id;
    latest_arrival_ = Clock::now();
    if (std::isfinite(sample->stamp)) latest_stamp_ = std::max(latest_stamp_, sample->stamp + time_offset_);
    take(*sample);
  }
  sample_arrived_.notify_all();
}

void ImuInput::take(const elo::ImuSample& sample) {
  if (mount_known_) {
    session_.addImu(sample);
    return;
  }
  held_.push_back(sample);
  while (held_.size() > 1 && !(held_.front().stamp >= held_.back().stamp - kHeldSeconds)) {
    held_.pop_front();
    statistics_.messageUnused(imu_message::kNoMount);
  }
}

void ImuInput::lookUpMount(const std::string& sensor_frame) {
  std::string imu_frame;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    imu_frame = imu_frame_;
  }
  if (imu_frame.empty()) return;  // no message yet: nothing to place
  Eigen::Isometry3d lidar_from_imu = Eigen::Isometry3d::Identity();
  if (imu_frame != sensor_frame) {
    // The first look waits for TF as the sensor's extrinsic does; later ones only ask.
    const double timeout = mount_tried_ ? 0.0 : settings_.tf_timeout;
    mount_tried_ = true;
    try {
      lidar_from_imu = tf2::transformToEigen(
          tf_buffer_->lookupTransform(sensor_frame, imu_frame, ros::Time(0), ros::Duration(timeout)));
    } catch (const tf2::TransformException& error) {
      ROS_WARN_THROTTLE_NAMED(kWarningPeriod, name_,
                              "no transform %s <- %s for the IMU (%s): its samples are not used and the scans keep "
                              "the LiDAR-only prior until TF has it (or set ~imu_mount_from_tf false and give "
                              "imu.position and imu.rotation_deg)",
                              sensor_frame.c_str(), imu_frame.c_str(), error.what());
      return;
    }
  }
  // R = Rz(yaw) Ry(pitch) Rx(roll): imu.rotation_deg's convention (elo::lidarFromImuRotation()). TF holds
  // no transform that is not finite (tf2 refuses them).
  const Eigen::Vector3d yaw_pitch_roll = lidar_from_imu.linear().eulerAngles(2, 1, 0);
  const Eigen::Vector3d& position = lidar_from_imu.translation();
  session_.setImuMount({position.x(), position.y(), position.z()},
                       degrees({yaw_pitch_roll.z(), yaw_pitch_roll.y(), yaw_pitch_roll.x()}));
  ROS_INFO_NAMED(name_, "IMU mount from TF: %s in %s at [%.3f, %.3f, %.3f] m", imu_frame.c_str(),
                 sensor_frame.c_str(), position.x(), position.y(), position.z());
  tf_listener_.reset();
  tf_buffer_.reset();
  std::lock_guard<std::mutex> lock(mutex_);
  mount_known_ = true;
  for (const elo::ImuSample& sample : held_) take(sample);
  held_.clear();
}

void ImuInput::beforeScan(const std::string& sensor_frame, double stamp) {
  const double sweep_end = stamp + sweep_end_;
  {
    std::unique_lock<std::mutex> lock(mutex_);
    // The first scan waits too: the IMU's first messages may come after it.
    const bool heard = first_scan_ || std::chrono::duration<double>(Clock::now() - latest_arrival_).count() < kHeardWithin;
    first_scan_ = false;
    if (heard) {
      sample_arrived_.wait_for(lock, std::chrono::duration<double>(settings_.imu_max_wait),
                               [&] { return latest_stamp_ >= sweep_end; });
    }
  }
  if (!mount_known_) lookUpMount(sensor_frame);  // mount_known_ changes on this thread only
}

}  // namespace elo_ros
