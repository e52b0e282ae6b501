// The Imu messages of a bag, ROS 1 (src/ros/ros1_bag.hpp) or ROS 2 (ros2_bag.hpp), as elo_run's IMU
// takes them (docs/imu.md): the samples in stamp order, and the messages that gave none, counted.
#pragma once

#include <map>
#include <string>
#include <vector>

#include "elo/imu/imu_track.hpp"

namespace elo {

// Why an Imu message gives no sample: the keys the node's diagnostics and elo_run count them under.
namespace imu_message {
inline constexpr char kNoAngularVelocity[] = "Imu message without angular velocity (its covariance[0] is -1)";
inline constexpr char kUnreadable[] = "Imu message unreadable";
}  // namespace imu_message

struct BagImu {
  std::string topic;                      // empty: the bag has no Imu topic
  std::vector<ImuSample> samples;         // in header-stamp order, once sortByStamp() ran
  std::map<std::string, size_t> skipped;  // messages that gave no sample, by reason (imu_message)
  std::string unreadable_detail;          // the first unreadable message: which, and what is wrong with it

  // Counts a message that gives no sample; `detail` kept for the first unreadable one.
  void skip(const std::string& reason, const std::string& detail = "");
  // A bag records messages as they arrived; the odometry takes the samples in the order of their stamps.
  void sortByStamp();
};

}  // namespace elo
