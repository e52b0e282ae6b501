#include "scan_sources.hpp"

#include <filesystem>

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

}  // namespace elo_ros
