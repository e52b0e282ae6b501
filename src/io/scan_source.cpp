#include "elo/io/scan_source.hpp"

#include <algorithm>
#include <iterator>
#include <stdexcept>

namespace elo {
namespace {

std::string listTopics(const std::vector<BagTopic>& topics) {
  std::string list;
  for (const BagTopic& topic : topics) {
    list += (list.empty() ? "" : ", ") + topic.name + " (" + topic.type + ", " + std::to_string(topic.messages) + " messages)";
  }
  return list.empty() ? "none" : list;
}

}  // namespace

std::string chooseCloudTopic(const std::string& bag, const std::vector<BagTopic>& topics, const std::string& cloud_type,
                             const std::string& requested) {
  std::vector<BagTopic> clouds;
  std::copy_if(topics.begin(), topics.end(), std::back_inserter(clouds),
               [&](const BagTopic& topic) { return topic.type == cloud_type; });
  if (!requested.empty()) {
    const bool found = std::any_of(clouds.begin(), clouds.end(), [&](const BagTopic& t) { return t.name == requested; });
    if (!found) throw IoError(bag + " has no " + cloud_type + " topic " + requested + "; its topics: " + listTopics(topics));
    return requested;
  }
  if (clouds.empty()) throw IoError(bag + " has no " + cloud_type + " topic; its topics: " + listTopics(topics));
  if (clouds.size() > 1) {
    throw IoError(bag + " has several " + cloud_type + " topics: " + listTopics(clouds) + "; choose one with --topic");
  }
  return clouds.front().name;
}

std::string chooseImuTopic(const std::string& bag, const std::vector<BagTopic>& topics, const std::string& imu_type,
                           const std::string& requested) {
  std::vector<BagTopic> imus;
  std::copy_if(topics.begin(), topics.end(), std::back_inserter(imus),
               [&](const BagTopic& topic) { return topic.type == imu_type; });
  if (!requested.empty()) {
    const bool found = std::any_of(imus.begin(), imus.end(), [&](const BagTopic& t) { return t.name == requested; });
    if (!found) throw IoError(bag + " has no " + imu_type + " topic " + requested + "; its topics: " + listTopics(topics));
    return requested;
  }
  if (imus.size() > 1) {
    throw IoError(bag + " has several " + imu_type + " topics: " + listTopics(imus) + "; choose one with --imu-topic");
  }
  return imus.empty() ? "" : imus.front().name;
}

std::vector<PlayedScan> playOrder(const ScanSource& source, size_t stride, bool reverse, size_t max_frames,
                                  size_t first) {
  if (stride == 0) throw std::invalid_argument("the stride between played scans must be at least 1");
  std::vector<PlayedScan> played;
  for (size_t index = first; index < source.size(); index += stride) played.push_back({index, source.stamp(index)});
  if (reverse && !played.empty()) {
    const double mirror = played.front().stamp + played.back().stamp;
    std::reverse(played.begin(), played.end());
    for (PlayedScan& scan : played) scan = {scan.index, mirror - scan.stamp, true};
  }
  if (max_frames > 0 && played.size() > max_frames) played.resize(max_frames);
  return played;
}

void asPlayed(const PlayedScan& played, PointCloud& cloud) {
  cloud.stamp = played.stamp;
  if (played.reversed) {
    for (float& time : cloud.time) time = -time;
  }
}

void reverseSweepDirection(SensorConfig& sensor) { sensor.clockwise = !sensor.clockwise; }

}  // namespace elo
