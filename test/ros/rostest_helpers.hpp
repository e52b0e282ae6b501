// Shared by the rostest nodes: replaying a bag's clouds to the odometry, collecting what it publishes,
// and running elo::Odometry in-process on the same scans for comparison.
#pragma once

#include <gtest/gtest.h>
#include <nav_msgs/Odometry.h>
#include <ros/ros.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <sensor_msgs/PointCloud2.h>
#include <tf2_eigen/tf2_eigen.h>

#include <chrono>
#include <condition_variable>
#include <filesystem>
#include <mutex>
#include <string>
#include <vector>

#include "elo/io/sequence.hpp"
#include "elo/pipeline/odometry.hpp"

namespace elo_ros_test {

using CloudMessages = std::vector<sensor_msgs::PointCloud2ConstPtr>;

inline CloudMessages readClouds(const std::string& bag_path, const std::string& topic) {
  rosbag::Bag bag(bag_path, rosbag::bagmode::Read);
  CloudMessages clouds;
  for (const rosbag::MessageInstance& instance : rosbag::View(bag, rosbag::TopicQuery(topic))) {
    clouds.push_back(instance.instantiate<sensor_msgs::PointCloud2>());
  }
  return clouds;
}

inline Eigen::Isometry3d poseOf(const nav_msgs::Odometry& odometry) {
  Eigen::Isometry3d pose;
  tf2::fromMsg(odometry.pose.pose, pose);
  return pose;
}

// Largest difference of translation (m) and rotation matrix entries between two poses.
inline double poseDifference(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b) {
  return std::max((a.translation() - b.translation()).cwiseAbs().maxCoeff(),
                  (a.linear() - b.linear()).cwiseAbs().maxCoeff());
}

// Collects the odometry messages and lets the test wait for a count.
class OdometryRecorder {
 public:
  OdometryRecorder(ros::NodeHandle& node, const std::string& topic)
      : subscriber_(node.subscribe(topic, 1000, &OdometryRecorder::onOdometry, this)) {}

  bool waitFor(size_t count, double timeout_seconds) {
    std::unique_lock<std::mutex> lock(mutex_);
    return arrived_.wait_for(lock, std::chrono::duration<double>(timeout_seconds),
                             [&] { return messages_.size() >= count; });
  }

  std::vector<nav_msgs::Odometry> messages() {
    std::lock_guard<std::mutex> lock(mutex_);
    return messages_;
  }

  void clear() {
    std::lock_guard<std::mutex> lock(mutex_);
    messages_.clear();
  }

  ros::Subscriber& subscriber() { return subscriber_; }

 private:
  void onOdometry(const nav_msgs::Odometry& odometry) {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      messages_.push_back(odometry);
    }
    arrived_.notify_all();
  }

  ros::Subscriber subscriber_;
  std::mutex mutex_;
  std::condition_variable arrived_;
  std::vector<nav_msgs::Odometry> messages_;
};

// Waits until the odometry listens on `publisher` and publishes on `recorder`'s topic.
inline bool waitForConnections(const ros::Publisher& publisher, OdometryRecorder& recorder, double timeout_seconds) {
  const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(timeout_seconds);
  while (ros::WallTime::now() < deadline) {
    if (publisher.getNumSubscribers() > 0 && recorder.subscriber().getNumPublishers() > 0) return true;
    ros::WallDuration(0.05).sleep();
  }
  return false;
}

// What elo_run computes over the first `scans` scans of `sequence`: each with its own stamp (times.txt).
// The nodelet sees the stamps of the bag's messages instead (kitti_to_bag's start time added, rounded to
// nanoseconds by ros::Time) and must give the same poses, the core counting time in whole nanoseconds
// since the first scan.
inline std::vector<Eigen::Isometry3d> runInProcess(const elo::Config& config, const elo::Sequence& sequence,
                                                   size_t scans) {
  elo::Odometry odometry(config);
  std::vector<Eigen::Isometry3d> poses;
  for (size_t i = 0; i < scans; ++i) poses.push_back(odometry.process(sequence.load(i)).pose);
  return poses;
}

}  // namespace elo_ros_test
