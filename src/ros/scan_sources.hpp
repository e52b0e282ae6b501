// Opens what elo_run's --input names: a ROS 1 bag (*.bag), a ROS 2 bag (a directory with metadata.yaml,
// or one of its .db3 files), or a sequence directory. Here, beside the ROS 1 reader, because only the ROS layer may read ROS 1 bags.
#pragma once

#include <map>
#include <memory>
#include <string>
#include <vector>

#include "elo/imu/imu_track.hpp"
#include "elo/io/scan_source.hpp"

namespace elo_ros {

// `topic`: the bag topic to read (empty: the bag's only PointCloud2 topic); a sequence directory has
// none, and naming one is an error. An .mcap file is refused with the command that converts it. Throws
// elo::IoError.
std::unique_ptr<elo::ScanSource> openScanSource(const std::string& input, const std::string& topic);

// The IMU samples of elo_run's input (imu.enabled, docs/imu.md), in stamp order.
struct ImuRecording {
  std::vector<elo::ImuSample> samples;
  std::string describe;                   // where they came from; empty when the input has none
  std::map<std::string, size_t> skipped;  // messages that gave no sample, by reason
  std::string unreadable_detail;          // the first message that could not be read: which, and why
  std::string warning;                    // why there are none (the LiDAR alone), or what part was lost
};

// From a bag (ROS 1, or ROS 2: a directory with metadata.yaml or one of its .db3 files), its Imu topic
// `imu_topic` (empty: its only one; none: a warning); from a directory, its imu.txt. Throws elo::IoError
// for a directory without imu.txt or with a malformed one, an `imu_topic` with an input that is no bag,
// or a bag's Imu topics that readRos1BagImu() or elo::readRos2BagImu() refuses.
ImuRecording readImuRecording(const std::string& input, const std::string& imu_topic);

}  // namespace elo_ros
