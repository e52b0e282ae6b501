#include "elo/sim/imu.hpp"

#include <cmath>

#include "elo/se3.hpp"
#include "elo/sim/rng.hpp"
#include "elo/sim/simulation.hpp"

namespace elo::sim {

namespace {

constexpr double kDegToRad = M_PI / 180.0;
constexpr double kStandardGravity = 9.81;  // m/s^2
constexpr double kMicroG = 9.81e-6;        // m/s^2
constexpr double kStep = 1e-3;             // s: the central differences' half step
// s: the accelerometers read the mean acceleration over this window, as their anti-aliasing filter
// (a bandwidth of about 50 Hz) makes a unit's do. The routes are piecewise linear (a sample every 5 cm):
// differenced at a millisecond, each corner between route samples read as a spike of hundreds of m/s^2;
// averaged, the window's acceleration integrates to the route's change of velocity.
constexpr double kAccelerometerWindow = 0.02;

Eigen::Vector3d gaussianVector(Rng& rng, double stddev) {
  return {rng.gaussian(0.0, stddev), rng.gaussian(0.0, stddev), rng.gaussian(0.0, stddev)};
}

// The IMU's true rate (its frame) from its pose a step either side of `t`, and its specific force at `t`:
// the acceleration over kAccelerometerWindow, gravity included.
ImuSample trueSample(const std::function<Eigen::Isometry3d(double)>& imu_pose_at, double t) {
  const Eigen::Isometry3d before = imu_pose_at(t - kStep);
  const Eigen::Isometry3d now = imu_pose_at(t);
  const Eigen::Isometry3d after = imu_pose_at(t + kStep);
  ImuSample sample;
  sample.stamp = t;
  sample.angular_velocity = logSO3(before.linear().transpose() * after.linear()) / (2.0 * kStep);
  const auto velocity_at = [&](double time) -> Eigen::Vector3d {
    return (imu_pose_at(time + kStep).translation() - imu_pose_at(time - kStep).translation()) / (2.0 * kStep);
  };
  const double half = 0.5 * kAccelerometerWindow;
  const Eigen::Vector3d acceleration = (velocity_at(t + half) - velocity_at(t - half)) / kAccelerometerWindow;
  sample.specific_force = now.linear().transpose() * (acceleration + Eigen::Vector3d(0.0, 0.0, kStandardGravity));
  return sample;
}

}  // namespace

ImuGrade consumerImu() {
  return {"consumer", 0.015 * kDegToRad, 0.5 * kDegToRad, 1e-4, 230.0 * kMicroG, 5000.0 * kMicroG, 1e-3};
}

ImuGrade industrialImu() {
  return {"industrial", 0.002 * kDegToRad, 0.05 * kDegToRad, 2e-6, 15.0 * kMicroG, 1000.0 * kMicroG, 3e-5};
}

std::optional<ImuGrade> imuGradeFromName(const std::string& name) {
  if (name == "consumer") return consumerImu();
  if (name == "industrial") return industrialImu();
  return std::nullopt;
}

std::vector<std::string> imuGradeNames() { return {"consumer", "industrial"}; }

std::vector<double> imuMountPosition() { return {-0.06, 0.03, -0.08}; }
std::vector<double> imuMountRotationDeg() { return {180.0, 0.0, 90.0}; }

Eigen::Isometry3d simulatedImuMount() {
  ImuConfig config;
  config.rotation_deg = imuMountRotationDeg();
  Eigen::Isometry3d mount = Eigen::Isometry3d::Identity();
  mount.linear() = lidarFromImuRotation(config);
  const std::vector<double> position = imuMountPosition();
  mount.translation() = Eigen::Vector3d(position[0], position[1], position[2]);
  return mount;
}

std::vector<ImuSample> simulateImu(const std::function<Eigen::Isometry3d(double)>& lidar_pose_at, double from,
                                   double to, double rate_hz, const ImuGrade& grade,
                                   const Eigen::Isometry3d& lidar_from_imu, uint64_t seed) {
  const auto imu_pose_at = [&](double t) { return lidar_pose_at(t) * lidar_from_imu; };
  Rng rng(mixSeed(seed, 0x1e0));
  const double period = 1.0 / rate_hz;
  Eigen::Vector3d gyro_bias = gaussianVector(rng, grade.gyro_bias);
  Eigen::Vector3d accel_bias = gaussianVector(rng, grade.accel_bias);
  const double gyro_noise = grade.gyro_noise_density * std::sqrt(rate_hz);
  const double accel_noise = grade.accel_noise_density * std::sqrt(rate_hz);
  std::vector<ImuSample> samples;
  for (long i = 0; from + i * period <= to; ++i) {
    ImuSample sample = trueSample(imu_pose_at, from + i * period);
    sample.angular_velocity += gyro_bias + gaussianVector(rng, gyro_noise);
    sample.specific_force += accel_bias + gaussianVector(rng, accel_noise);
    samples.push_back(sample);
    gyro_bias += gaussianVector(rng, grade.gyro_bias_walk * std::sqrt(period));
    accel_bias += gaussianVector(rng, grade.accel_bias_walk * std::sqrt(period));
  }
  return samples;
}

std::vector<ImuSample> simulateImu(const Simulation& simulation, const ImuGrade& grade, double rate_hz, uint64_t seed) {
  const double period = simulation.lidar().sweepDuration();
  const int last = simulation.frameCount() - 1;
  return simulateImu([&](double t) { return simulation.trajectory().poseAt(t); }, simulation.sweepStart(0) - period,
                     simulation.stamp(last) + period, rate_hz, grade, simulatedImuMount(), seed);
}

}  // namespace elo::sim
