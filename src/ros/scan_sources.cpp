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

ImuRecording readImuRecording(const std::string& input, const std::string& imu_topic) {
  ImuRecording recording;
  const std::filesystem::path path(input);
  if (path.extension() == ".bag") {
    BagImu bag = readRos1BagImu(input, imu_topic);
    if (bag.topic.empty()) {
      recording.warning = "imu.enabled, but bag '" + input + "' has no sensor_msgs/Imu topic: the LiDAR alone";
      return recording;
    }
    recording.samples = std::move(bag.samples);
    recording.skipped = std::move(bag.skipped);
    recording.describe = "bag '" + input + "', topic " + bag.topic;
    return recording;
  }
  if (!imu_topic.empty()) throw elo::IoError("--imu-topic names a ROS 1 bag's topic, but '" + input + "' is not one");
  if (path.extension() == ".db3" || elo::isRos2Bag(input)) {
    recording.warning = "imu.enabled, but elo_run does not read the IMU of a ROS 2 bag: the LiDAR alone";
    return recording;
  }
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
