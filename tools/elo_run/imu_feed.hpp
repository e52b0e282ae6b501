// elo_run's IMU (imu.enabled, docs/imu.md): the samples of the input directory's imu.txt or of the input
// bag's sensor_msgs/Imu topic, handed to the drive session before each scan, up to the end of its sweep.
#pragma once

#include <map>
#include <string>
#include <vector>

#include "elo/drive_session.hpp"
#include "options.hpp"

namespace elo::tools {

class ImuFeed {
 public:
  // Reads the samples when `config.imu.enabled` (elo_ros::readImuRecording(), --imu-topic) and says where
  // from, or why there are none. Throws UsageError for --imu-topic without imu.enabled, IoError as
  // readImuRecording() does.
  ImuFeed(const Options& options, const Config& config);

  // Hands `session` every sample not handed yet up to a sweep and a half after `stamp` (the scan's).
  void feedUpTo(double stamp, DriveSession& session);
  // Bag messages that gave no sample, by reason.
  const std::map<std::string, size_t>& skippedMessages() const { return skipped_; }

 private:
  double sweep_;       // s
  double time_offset_;  // imu.time_offset
  std::vector<ImuSample> samples_;
  std::map<std::string, size_t> skipped_;
  size_t next_ = 0;
};

}  // namespace elo::tools
