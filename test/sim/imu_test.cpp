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

// On the hard-driven car (0.8 g of braking, a route of straight pieces every 5 cm), a flawless unit's
// accelerometers, integrated through its gyro over each 0.1 s, give the route's change of velocity: the
// corners between route samples are averaged over the accelerometers' window, not read as spikes.
TEST(SimulatedImu, TheAccelerometersIntegrateToTheHardDrivenCarsChangeOfVelocity) {
  const Route route = proceduralRoute(TrajectoryKind::hard_driving, 10.0, 40.0);
  const auto pose_at = [&route](double t) {
    const Pose2 pose = route.at(t);
    Eigen::Isometry3d lidar = Eigen::Isometry3d::Identity();
    lidar.linear() = Eigen::AngleAxisd(pose.heading, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    lidar.translation() = Eigen::Vector3d(pose.x, pose.y, 1.5);
    return lidar;
  };
  const ImuGrade flawless{"flawless", 0.0, 0.0, 0.0, 0.0, 0.0, 0.0};
  ImuTrack track{ImuConfig()};
  for (const ImuSample& sample : simulateImu(pose_at, 0.0, 40.0, 200.0, flawless, Eigen::Isometry3d::Identity(), 1)) {
    ASSERT_EQ(track.add(sample), "");
  }
  const auto velocity_at = [&](double t) -> Eigen::Vector3d {
    // The mean velocity over the accelerometers' 20 ms window, whose change they integrate to.
    return (pose_at(t + 0.01).translation() - pose_at(t - 0.01).translation()) / 0.02;
  };
  double worst = 0.0, largest_change = 0.0;
  for (double t = 1.0; t + 1.1 < 40.0; t += 0.1) {
    Preintegration motion;
    ASSERT_EQ(track.preintegrate(t, t + 1.0, motion), "");
    const Eigen::Vector3d change =
        pose_at(t).linear() * motion.velocity + Eigen::Vector3d(0.0, 0.0, -9.81) * motion.duration;
    const Eigen::Vector3d truth = velocity_at(t + 1.0) - velocity_at(t);
    worst = std::max(worst, (change - truth).norm());
    largest_change = std::max(largest_change, truth.norm());
  }
  std::printf("[ sim imu  ] hard-driven car: velocity change over 1 s up to %.2f m/s, accelerometers off by %.3f m/s at most\n",
              largest_change, worst);
  EXPECT_GT(largest_change, 5.0);
  EXPECT_LT(worst, 0.06);  // 0.041 m/s
}

}  // namespace
}  // namespace elo::sim
