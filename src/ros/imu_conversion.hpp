// sensor_msgs/Imu <-> the core's ImuSample (docs/imu.md), for the node's `imu` topic, elo_run's bags and
// elo_sim's.
#pragma once

#include <sensor_msgs/Imu.h>

#include <optional>
#include <string>

#include "elo/imu/imu_track.hpp"
#include "elo/io/bag_imu.hpp"

namespace elo_ros {

// Why an Imu message gives no sample: the core's keys (elo/io/bag_imu.hpp), which a ROS 2 bag's messages
// are counted under too.
namespace imu_message {
using elo::imu_message::kNoAngularVelocity;
using elo::imu_message::kUnreadable;
}  // namespace imu_message

// The sample an Imu message holds: its header stamp, angular_velocity (rad/s) and linear_acceleration
// (m/s^2, specific force: gravity included, as REP-145 has it), in the message's frame. Empty, with
// `problem` set, for a message that says it has no angular velocity (REP-145: covariance[0] = -1).
std::optional<elo::ImuSample> imuSampleOf(const sensor_msgs::Imu& message, std::string& problem);

// The message of a sample: frame `frame_id`, no orientation (orientation_covariance[0] = -1, as REP-145
// asks of an IMU without one), covariances unknown (zero).
sensor_msgs::Imu imuMessageOf(const elo::ImuSample& sample, const std::string& frame_id);

}  // namespace elo_ros
