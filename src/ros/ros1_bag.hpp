// A ROS 1 bag as a source of scans: its sensor_msgs/PointCloud2 messages on one topic, read with the
// rosbag storage library (no master, no clock) in header-stamp order, and converted as the nodelet
// converts them (cloud_conversion.hpp).
#pragma once

#include <rosbag/bag.h>
#include <rosbag/message_instance.h>
#include <rosbag/view.h>

#include <string>
#include <vector>

#include "elo/io/bag_imu.hpp"
#include "elo/io/scan_source.hpp"

namespace elo_ros {

class Ros1Bag : public elo::ScanSource {
 public:
  // Opens `path` and lists the clouds of `topic` (empty: the bag's only PointCloud2 topic) in
  // header-stamp order. Throws elo::IoError for a bag rosbag cannot open (a truncated bag has lost its
  // index: `rosbag reindex` restores it), no such topic (the message lists the bag's topics) or no
  // message on it.
  Ros1Bag(const std::string& path, const std::string& topic);

  size_t size() const override { return messages_.size(); }
  double stamp(size_t index) const override { return messages_.at(index).stamp; }
  // The message as the nodelet converts it; elo::UnusableScan when it cannot be read or used.
  elo::LoadedScan read(size_t index) const override;
  std::string describe() const override { return "bag '" + path_ + "', topic " + topic_; }

 private:
  struct Message {
    size_t position;  // in recording order: its index in instances_
    double stamp;     // the header stamp; the recording time when the message is unreadable
  };

  void listMessages();

  std::string path_;
  std::string topic_;
  rosbag::Bag bag_;
  std::vector<rosbag::MessageInstance> instances_;  // valid while bag_ is open
  std::vector<Message> messages_;                  // in stamp order
};

// The sensor_msgs/Imu messages of a ROS 1 bag, for elo_run's IMU (docs/imu.md): the samples of `topic` (empty: the bag's only sensor_msgs/Imu topic; none when it has none).
// Throws elo::IoError for a bag rosbag cannot open, a `topic` that is no Imu topic of the bag (the message
// lists its topics), or several Imu topics and none named (the message lists them).
elo::BagImu readRos1BagImu(const std::string& path, const std::string& topic);

}  // namespace elo_ros
