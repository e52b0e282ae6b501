// sensor_msgs/msg/Imu as ROS 2 serializes it in a bag: plain CDR (XCDR1), little- or big-endian as its
// 4-byte encapsulation header says (the reader cdr_point_cloud2.hpp's decoder shares). A decoder of our
// own (Debian 12 has no ROS 2): it reads untrusted bytes, so every read is checked against what is left,
// and test/fuzz/fuzz_cdr_imu fuzzes it.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <cstdint>

namespace elo {

// What elo_run takes of an Imu message (docs/imu.md, "Formats"); the orientation and the covariances but
// one are read past.
struct CdrImu {
  double stamp = 0.0;  // header.stamp, s, as ros::Time::toSec() gives it (stampSeconds())
  Eigen::Vector3d angular_velocity = Eigen::Vector3d::Zero();     // rad/s, in header.frame_id's axes
  Eigen::Vector3d linear_acceleration = Eigen::Vector3d::Zero();  // m/s^2, specific force (REP-145)
  // False when angular_velocity_covariance[0] is -1: REP-145's "this IMU gives no angular velocity".
  bool has_angular_velocity = true;
};

// Throws IoError naming what is malformed and at which byte (cut short, an encapsulation other than
// plain CDR).
CdrImu decodeCdrImu(const uint8_t* data, size_t size);

}  // namespace elo
