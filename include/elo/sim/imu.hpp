// The IMU a simulated sensor carries (docs/imu.md): its samples as a unit bolted to the LiDAR measures
// the motion, with white noise, a turn-on bias and a bias random walk for two grades, mounted with an
// offset and a rotation.
#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "elo/imu/imu_track.hpp"

namespace elo::sim {

// Noise densities and biases of a grade, per axis: white noise (per root hertz; a sample at rate r has
// standard deviation density * sqrt(r)), the turn-on bias's standard deviation, and the bias random walk
// (per root second).
struct ImuGrade {
  std::string name;
  double gyro_noise_density;  // rad/s/sqrt(Hz)
  double gyro_bias;           // rad/s
  double gyro_bias_walk;      // rad/s/sqrt(s)
  double accel_noise_density;  // m/s^2/sqrt(Hz)
  double accel_bias;           // m/s^2
  double accel_bias_walk;      // m/s^2/sqrt(s)
};

// The consumer MEMS built into LiDARs (an Ouster's or a Hesai's): 0.015 deg/s/sqrt(Hz), +-0.5 deg/s of
// bias; 230 ug/sqrt(Hz), 5 mg.
ImuGrade consumerImu();
// An industrial unit: 0.002 deg/s/sqrt(Hz), 0.05 deg/s of bias; 15 ug/sqrt(Hz), 1 mg.
ImuGrade industrialImu();
std::optional<ImuGrade> imuGradeFromName(const std::string& name);  // "consumer", "industrial"
std::vector<std::string> imuGradeNames();

// Where the simulated IMU sits on the LiDAR: 6 cm behind, 3 cm left and 8 cm below its origin, upside
// down and turned a quarter (roll 180 deg, yaw 90 deg): as imu.position and imu.rotation_deg say it.
Eigen::Isometry3d simulatedImuMount();
std::vector<double> imuMountPosition();
std::vector<double> imuMountRotationDeg();

// The samples, every 1 / rate_hz seconds over [from, to], of an IMU mounted at `lidar_from_imu` on a
// LiDAR whose pose in the world `lidar_pose_at(t)` gives: the rates and the specific force (gravity
// 9.81 m/s^2 along the world's -z included) of the IMU's own motion, by central differences over a
// millisecond, with the grade's noise and biases drawn from `seed`.
std::vector<ImuSample> simulateImu(const std::function<Eigen::Isometry3d(double)>& lidar_pose_at, double from,
                                   double to, double rate_hz, const ImuGrade& grade,
                                   const Eigen::Isometry3d& lidar_from_imu, uint64_t seed);

class Simulation;
// The IMU of `simulation`'s sensor (simulatedImuMount()) over its drive: from a scan period before its
// first sweep (the vehicle standing, a gait already moving the sensor) to a period after its last scan's
// stamp, on the clock of its stamps.
std::vector<ImuSample> simulateImu(const Simulation& simulation, const ImuGrade& grade, double rate_hz, uint64_t seed);

}  // namespace elo::sim
