#include "scan_sources.hpp"

#include <filesystem>

#include "elo/io/imu_file.hpp"
#include "elo/io/ros2_bag.hpp"
#include "elo/io/sequence.hpp"
#include "ros1_bag.hpp"

namespace elo_ros {

std::unique_ptr<elo::ScanSource> openScanSource(const std::string& input, const std::string& topic) {
  const std::string extension = std::filesystem::path(input).extension().string();
  if (extension == ".mcap") {
    throw elo::IoError("'" + input + "' is an MCAP bag, which elo_run does not read: convert it to SQLite with "
                       "`ros2 bag convert` (storage_id: sqlite3)");
  }
  if (extension == ".bag") return std::make_unique<Ros1Bag>(input, topic);
  if (extension == ".db3") {  // a file of a ROS 2 bag: the bag is its directory
    return std::make_unique<elo::Ros2Bag>(std::filesystem::absolute(input).parent_path().string(), topic);
  }
  if (elo::isRos2Bag(input)) return std::make_unique<elo::Ros2Bag>(input, topic);
  if (!topic.empty()) throw elo::IoError("--topic names a bag topic, but '" + input + "' is not a bag");
  return std::make_unique<elo::Sequence>(input);
}

namespace {

// A bag's Imu topic as elo_run takes it: its samples and skipped messages, or a warning when it has none.
ImuRecording recordingOf(elo::BagImu bag, const std::string& input, ImuRecording recording) {
  if (bag.topic.empty()) {
    recording.warning = "imu.enabled, but bag '" + input + "' has no sensor_msgs/Imu topic: the LiDAR alone";
    return recording;
  }
  recording.samples = std::move(bag.samples);
  recording.skipped = std::move(bag.skipped);
  recording.unreadable_detail = std::move(bag.unreadable_detail);
  recording.describe = "bag '" + input + "', topic " + bag.topic;
  return recording;
}

}  // namespace

ImuRecording readImuRecording(const std::string& input, const std::string& imu_topic) {
  ImuRecording recording;
  const std::filesystem::path path(input);
  if (path.extension() == ".bag") return recordingOf(readRos1BagImu(input, imu_topic), input, recording);
  if (path.extension() == ".db3" || elo::isRos2Bag(input)) {
    // A .db3 file is one file of a ROS 2 bag: the bag is its directory, as openScanSource() reads it.
    const std::string bag = elo::isRos2Bag(input) ? input : std::filesystem::absolute(path).parent_path().string();
    elo::BagImu imu = elo::readRos2BagImu(bag, imu_topic, recording.warning);
    return recordingOf(std::move(imu), bag, recording);
  }
  if (!imu_topic.empty()) throw elo::IoError("--imu-topic names a bag's topic, but '" + input + "' is not a bag");
  const std::filesystem::path file = path / "imu.txt";
  if (!std::filesystem::is_regular_file(file)) {
    throw elo::IoError("imu.enabled, but " + file.string() +
                       " is not there: elo_run reads the IMU from a KITTI-layout directory's imu.txt or a ROS 1 bag's "
                       "sensor_msgs/Imu topic (docs/imu.md)");
  }
  recording.samples = elo::readImuFile(file.string());
  recording.describe = file.string();
  return recording;
}

}  // namespace elo_ros
