#include "imu_conversion.hpp"

namespace elo_ros {

std::optional<elo::ImuSample> imuSampleOf(const sensor_msgs::Imu& message, std::string& problem) {
  if (message.angular_velocity_covariance[0] == -1.0) {
    problem = imu_message::kNoAngularVelocity;
    return std::nullopt;
  }
  elo::ImuSample sample;
  sample.stamp = message.header.stamp.toSec();
  sample.angular_velocity = {message.angular_velocity.x, message.angular_velocity.y, message.angular_velocity.z};
  sample.specific_force = {message.linear_acceleration.x, message.linear_acceleration.y,
                           message.linear_acceleration.z};
  return sample;
}

sensor_msgs::Imu imuMessageOf(const elo::ImuSample& sample, const std::string& frame_id) {
  sensor_msgs::Imu message;
  message.header.stamp.fromSec(sample.stamp);
  message.header.frame_id = frame_id;
  message.orientation_covariance[0] = -1.0;
  message.angular_velocity.x = sample.angular_velocity.x();
  message.angular_velocity.y = sample.angular_velocity.y();
  message.angular_velocity.z = sample.angular_velocity.z();
  message.linear_acceleration.x = sample.specific_force.x();
  message.linear_acceleration.y = sample.specific_force.y();
  message.linear_acceleration.z = sample.specific_force.z();
  return message;
}

}  // namespace elo_ros
