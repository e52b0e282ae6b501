#include "ros1_bag.hpp"

#include <ros/message_traits.h>
#include <sensor_msgs/Imu.h>
#include <sensor_msgs/PointCloud2.h>
#include <std_msgs/Header.h>

#include <algorithm>
#include <map>
#include <optional>

#include "cloud_conversion.hpp"
#include "imu_conversion.hpp"

// The header of a sensor_msgs/PointCloud2 alone. It is the message's first field, so deserializing just it
// from a bag reads a few bytes of each cloud rather than copying megabytes of points: listing a bag's
// clouds in stamp order costs one read of each chunk. The "*" MD5 sum lets rosbag hand it any cloud.
namespace elo_ros {
struct CloudHeader {
  std_msgs::Header header;
};
}  // namespace elo_ros

namespace ros {
namespace message_traits {
template <>
struct MD5Sum<elo_ros::CloudHeader> {
  static const char* value() { return "*"; }
  static const char* value(const elo_ros::CloudHeader&) { return value(); }
};
template <>
struct DataType<elo_ros::CloudHeader> {
  static const char* value() { return DataType<sensor_msgs::PointCloud2>::value(); }
  static const char* value(const elo_ros::CloudHeader&) { return value(); }
};
template <>
struct Definition<elo_ros::CloudHeader> {
  static const char* value() { return Definition<sensor_msgs::PointCloud2>::value(); }
  static const char* value(const elo_ros::CloudHeader&) { return value(); }
};
}  // namespace message_traits

namespace serialization {
template <>
struct Serializer<elo_ros::CloudHeader> {
  template <typename Stream>
  static void read(Stream& stream, elo_ros::CloudHeader& message) {
    stream.next(message.header);
  }
};
}  // namespace serialization
}  // namespace ros

namespace elo_ros {
namespace {

using CloudType = ros::message_traits::DataType<sensor_msgs::PointCloud2>;
using ImuType = ros::message_traits::DataType<sensor_msgs::Imu>;

std::vector<elo::BagTopic> topicsOf(const rosbag::Bag& bag) {
  std::map<std::string, elo::BagTopic> topics;
  for (const rosbag::ConnectionInfo* connection : rosbag::View(bag).getConnections()) {
    topics[connection->topic] = {connection->topic, connection->datatype, 0};
  }
  for (auto& [name, topic] : topics) topic.messages = rosbag::View(bag, rosbag::TopicQuery(name)).size();
  std::vector<elo::BagTopic> list;
  for (const auto& [name, topic] : topics) list.push_back(topic);
  return list;
}

void openBag(rosbag::Bag& bag, const std::string& path) {
  try {
    bag.open(path, rosbag::bagmode::Read);
  } catch (const rosbag::BagException& error) {
    throw elo::IoError("cannot read bag '" + path + "': " + error.what() +
                       " (a bag cut short has lost its index: `rosbag reindex` restores what it holds)");
  }
}

}  // namespace

elo::BagImu readRos1BagImu(const std::string& path, const std::string& topic) {
  rosbag::Bag bag;
  openBag(bag, path);
  elo::BagImu imu;
  imu.topic = elo::chooseImuTopic("bag '" + path + "'", topicsOf(bag), ImuType::value(), topic);
  if (imu.topic.empty()) return imu;
  for (const rosbag::MessageInstance& instance : rosbag::View(bag, rosbag::TopicQuery(imu.topic))) {
    std::string problem;
    std::optional<elo::ImuSample> sample;
    try {
      if (const auto message = instance.instantiate<sensor_msgs::Imu>()) sample = imuSampleOf(*message, problem);
    } catch (const std::exception& error) {
      // A message cut short or of another layout: counted, as a cloud that cannot be read is skipped.
      imu.skip(imu_message::kUnreadable, "bag '" + path + "', topic " + imu.topic + ", the message recorded at " +
                            std::to_string(instance.getTime().toSec()) + " s: " + error.what());
      continue;
    }
    if (sample) {
      imu.samples.push_back(*sample);
    } else {
      imu.skip(problem.empty() ? imu_message::kUnreadable : problem);
    }
  }
  imu.sortByStamp();
  return imu;
}

Ros1Bag::Ros1Bag(const std::string& path, const std::string& topic) : path_(path) {
  openBag(bag_, path_);
  topic_ = elo::chooseCloudTopic("bag '" + path_ + "'", topicsOf(bag_), CloudType::value(), topic);
  listMessages();
  if (messages_.empty()) throw elo::IoError(describe() + " holds no message");
}

// Reads the header stamp of every message of the topic (a bag records messages in the order they arrived,
// which need not be their stamps' order) and sorts them by it.
void Ros1Bag::listMessages() {
  // A MessageInstance refers to the bag, not to the view: the copies stay valid while bag_ is open.
  for (const rosbag::MessageInstance& instance : rosbag::View(bag_, rosbag::TopicQuery(topic_))) {
    double stamp = instance.getTime().toSec();
    try {
      if (const auto cloud = instance.instantiate<CloudHeader>()) stamp = cloud->header.stamp.toSec();
    } catch (const std::exception&) {
      // An unreadable message keeps its recording time; reading it says what is wrong.
    }
    messages_.push_back({instances_.size(), stamp});
    instances_.push_back(instance);
  }
  std::stable_sort(messages_.begin(), messages_.end(),
                   [](const Message& a, const Message& b) { return a.stamp < b.stamp; });
}

elo::LoadedScan Ros1Bag::read(size_t index) const {
  const Message& message = messages_.at(index);
  const std::string where = describe() + ", message " + std::to_string(message.position);
  sensor_msgs::PointCloud2::ConstPtr cloud;
  try {
    cloud = instances_[message.position].instantiate<sensor_msgs::PointCloud2>();
  } catch (const std::exception& error) {
    throw elo::UnusableScan("message unreadable", where + ": " + error.what());
  }
  if (!cloud) throw elo::UnusableScan("message unreadable", where + ": not a " + CloudType::value() + " message");
  ConvertedCloud converted = fromPointCloud2(*cloud);
  if (!converted.usable()) throw elo::UnusableScan(elo::describe(converted.problem), where + ": " + converted.detail);
  return {std::move(converted.cloud), converted.non_finite_points, converted.time_problem};
}

}  // namespace elo_ros
