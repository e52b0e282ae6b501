// The simulated IMU (docs/imu.md) against the simulator's own motion: an industrial unit's gyro,
// integrated between two scans of a hand-held walk, turns the LiDAR as the ground truth does to within
// its noise and bias; a consumer unit's within its larger ones; at rest, the accelerometers read gravity
// in the IMU's (upside-down) axes.
#include <gtest/gtest.h>

#include <cmath>

#include "elo/imu/imu_track.hpp"
#include "elo/sim/imu.hpp"
#include "elo/sim/sensors.hpp"
#include "elo/sim/simulation.hpp"

namespace elo::sim {
namespace {

SimulationSpec walkSpec(int frames) {
  SimulationSpec spec;
  spec.world = WorldFamily::urban;
  spec.frames = frames;
  loadSensor("vlp16", spec.config);
  spec.gait = handheldWalk();
  return spec;
}

// The largest angle (deg) between the gyro's rotation from scan to scan and the truth's, over a walk.
double worstTurnError(const Simulation& simulation, const ImuGrade& grade) {
  ImuConfig mount;
  mount.rotation_deg = imuMountRotationDeg();
  ImuTrack track(mount);
  for (const ImuSample& sample : simulateImu(simulation, grade, 200.0, 5)) EXPECT_EQ(track.add(sample), "");
  double worst = 0.0;
  for (int frame = 1; frame < simulation.frameCount(); ++frame) {
    Eigen::Matrix3d turned;
    EXPECT_EQ(track.rotation(simulation.stamp(frame - 1), simulation.stamp(frame), turned), "");
    const Eigen::Matrix3d truth =
        (simulation.sensorPose(frame - 1).inverse() * simulation.sensorPose(frame)).linear();
    worst = std::max(worst, Eigen::AngleAxisd(turned.transpose() * truth).angle() * 180.0 / M_PI);
  }
  return worst;
}

TEST(SimulatedImu, TheGyroTurnsAsTheWalkDoes) {
  const Simulation simulation(walkSpec(40));
  const double industrial = worstTurnError(simulation, industrialImu());
  const double consumer = worstTurnError(simulation, consumerImu());
  std::printf("[ sim imu  ] worst scan-to-scan turn error over a hand-held walk: industrial %.4f deg, consumer %.4f deg\n",
              industrial, consumer);
  EXPECT_LT(industrial, 0.02);  // 0.05 deg/s of bias at most over 0.1 s, and the noise
  EXPECT_LT(consumer, 0.2);     // 2 deg/s (four standard deviations) over 0.1 s, and the noise
  EXPECT_GT(consumer, industrial);
}

TEST(SimulatedImu, AtRestTheAccelerometersReadGravityInTheImuAxes) {
  const auto standing = [](double) { return Eigen::Isometry3d::Identity(); };
  const std::vector<ImuSample> samples =
      simulateImu(standing, 0.0, 1.0, 100.0, industrialImu(), simulatedImuMount(), 9);
  ASSERT_EQ(samples.size(), 101u);
  Eigen::Vector3d mean_force = Eigen::Vector3d::Zero();
  for (const ImuSample& sample : samples) mean_force += sample.specific_force / samples.size();
  // Upside down: the IMU's z points at the ground, so the force that holds it up reads along -z.
  EXPECT_LT((mean_force - Eigen::Vector3d(0.0, 0.0, -9.81)).norm(), 0.05);
  EXPECT_LT(samples.back().angular_velocity.norm(), 0.01);
}

}  // namespace
}  // namespace elo::sim
