// What the accelerometers say of the motion (docs/imu.md): ImuTrack::preintegrate() exactly on a
// constant specific force through the mount, and to the integrator's order on a turning one; the
// InertialFilter's velocity, gravity and prior translation on a motion of constant acceleration in a
// world frame that is not level.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "elo/imu/imu_track.hpp"
#include "elo/imu/inertial_filter.hpp"

namespace elo {
namespace {

constexpr double kRate = 200.0;  // Hz

ImuConfig mountedUpsideDownAndTurned() {
  ImuConfig config;
  config.rotation_deg = {180.0, 0.0, 90.0};
  config.position = {-0.06, 0.03, -0.08};
  return config;
}

ImuSample sampleAt(double stamp, const Eigen::Vector3d& rate, const Eigen::Vector3d& force) {
  ImuSample sample;
  sample.stamp = stamp;
  sample.angular_velocity = rate;
  sample.specific_force = force;
  return sample;
}

TEST(ImuPreintegration, AConstantSpecificForceIsIntegratedExactlyThroughTheMount) {
  const ImuConfig config = mountedUpsideDownAndTurned();
  ImuTrack track(config);
  const Eigen::Vector3d force(1.0, -2.0, 9.81);  // IMU axes
  for (int i = 0; i <= 200; ++i) ASSERT_EQ(track.add(sampleAt(i / kRate, Eigen::Vector3d::Zero(), force)), "");
  Preintegration motion;
  ASSERT_EQ(track.preintegrate(0.1234, 0.3734, motion), "");
  const Eigen::Vector3d in_lidar = lidarFromImuRotation(config) * force;
  EXPECT_NEAR(motion.duration, 0.25, 1e-15);
  EXPECT_LT((motion.velocity - in_lidar * 0.25).norm(), 1e-12);
  EXPECT_LT((motion.position - 0.5 * in_lidar * 0.25 * 0.25).norm(), 1e-12);
  EXPECT_LT((motion.velocity_by_bias - 0.25 * Eigen::Matrix3d::Identity()).norm(), 1e-12);
  EXPECT_LT((motion.position_by_bias - 0.5 * 0.25 * 0.25 * Eigen::Matrix3d::Identity()).norm(), 1e-12);
}

// Turning at 2 rad/s about the vertical while the specific force stays fixed in the world (gravity and a
// steady push along x): integrated through the turn, it is that fixed force times the time.
TEST(ImuPreintegration, ATurningSensorIntegratesTheForceInTheStartFrame) {
  ImuTrack track{ImuConfig()};
  const Eigen::Vector3d in_world(1.5, 0.0, 9.81);
  const double rate = 2.0;
  for (int i = 0; i <= 200; ++i) {
    const double t = i / kRate;
    const Eigen::Matrix3d turn = Eigen::AngleAxisd(rate * t, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    ASSERT_EQ(track.add(sampleAt(t, Eigen::Vector3d(0.0, 0.0, rate), turn.transpose() * in_world)), "");
  }
  Preintegration motion;
  ASSERT_EQ(track.preintegrate(0.0, 0.5, motion), "");
  const Eigen::Matrix3d start = Eigen::Matrix3d::Identity();
  EXPECT_LT((motion.velocity - start * in_world * 0.5).norm(), 1e-3);
  EXPECT_LT((motion.position - 0.5 * in_world * 0.25).norm(), 1e-4);
  EXPECT_LT(Eigen::AngleAxisd(motion.rotation.transpose() *
                              Eigen::AngleAxisd(1.0, Eigen::Vector3d::UnitZ()).toRotationMatrix()).angle(), 1e-12);
}

TEST(ImuPreintegration, ASaturatedAccelerometerDropsTheSample) {
  ImuConfig config;
  config.accel_limit = 80.0;
  ImuTrack track(config);
  EXPECT_EQ(track.add(sampleAt(0.0, Eigen::Vector3d::Zero(), Eigen::Vector3d(0.0, 85.0, 9.81))),
            imu_issue::kAccelSaturated);
  config.accelerometer = false;  // unused, the accelerometers cannot spoil the gyro's samples
  ImuTrack gyro_only(config);
  EXPECT_EQ(gyro_only.add(sampleAt(0.0, Eigen::Vector3d::Zero(), Eigen::Vector3d(0.0, 85.0, 9.81))), "");
}

// The LiDAR speeds up at 0.8 m/s^2 along x from 2 m/s, without turning, in an odometry world whose axes
// are tilted 10 deg from level; the IMU sits off its origin, turned (mountedUpsideDownAndTurned()).
// The registered translations are exact; the filter finds the velocity, and its prior translation the
// next scan's, to a millimetre after a second and a tenth of one after three.
TEST(InertialFilter, AConstantAccelerationIsPredictedInATiltedWorld) {
  const ImuConfig config = mountedUpsideDownAndTurned();
  InertialFilter filter(config);
  const Eigen::Matrix3d tilt = Eigen::AngleAxisd(10.0 * M_PI / 180.0, Eigen::Vector3d(1.0, 1.0, 0.0).normalized())
                                   .toRotationMatrix();
  const Eigen::Vector3d gravity = tilt.transpose() * Eigen::Vector3d(0.0, 0.0, -9.81);  // in the odometry world
  const Eigen::Vector3d acceleration(0.8, 0.0, 0.0);
  const double dt = 0.1;
  Preintegration motion;
  motion.duration = dt;
  motion.velocity = (acceleration - gravity) * dt;  // the attitude is the identity throughout
  motion.position = 0.5 * (acceleration - gravity) * dt * dt;
  motion.velocity_by_bias = Eigen::Matrix3d::Identity() * dt;
  motion.position_by_bias = Eigen::Matrix3d::Identity() * 0.5 * dt * dt;
  const Eigen::Matrix3d attitude = Eigen::Matrix3d::Identity();
  Eigen::Vector3d velocity(2.0, 0.0, 0.0);
  for (int scan = 0; scan < 40; ++scan) {
    Eigen::Isometry3d registered = Eigen::Isometry3d::Identity();
    registered.translation() = velocity * dt + 0.5 * acceleration * dt * dt;
    if (scan >= 2) {
      EXPECT_TRUE(filter.ready());
      EXPECT_LT((filter.predictTranslation(motion, attitude, Eigen::Matrix3d::Identity()) - registered.translation()).norm(),
                scan >= 30 ? 1e-4 : scan >= 10 ? 1e-3 : 2e-2)
          << "scan " << scan;
    } else {
      EXPECT_FALSE(filter.ready());
    }
    filter.update(motion, attitude, registered);
    velocity += acceleration * dt;
  }
  EXPECT_LT((filter.velocity() - velocity).norm(), 1e-3);
  filter.forgetVelocity();
  EXPECT_FALSE(filter.ready());
  EXPECT_TRUE(filter.started());
}

// The gate (imu.accel_gate) on the same motion, the LiDAR-only prior the constant velocity (the last
// registered translation again, a dt^2 = 8 mm short each scan). Fed the consistent force, no interval is
// gated. One impulse in the force (an aliased sample: 100 m/s^2 read over 5 ms at the interval's middle,
// 0.5 m/s the IMU never made) puts that interval's prediction 25 mm off: it is gated and counted, the filter
// is not ready() for the next two scans (their prior is the LiDAR's), then predicts within a centimetre
// again. Without the gate, the impulse's velocity misleads the next scan's prior by 2 cm and more.
struct GatedDrive {
  std::vector<int> gated;           // the scans whose interval was gated
  std::vector<int> not_ready;       // the scans after the first two whose prior was not the filter's
  double worst_after_impulse = 0.0;  // m, the filter's prior against the truth, the scans after the impulse
};

GatedDrive driveWithAnImpulse(const ImuConfig& config, int impulse_scan) {
  const Eigen::Vector3d gravity(0.0, 0.0, -9.81);
  const Eigen::Vector3d acceleration(0.8, 0.0, 0.0);
  const double dt = 0.1;
  Preintegration motion;
  motion.duration = dt;
  motion.velocity = (acceleration - gravity) * dt;
  motion.position = 0.5 * (acceleration - gravity) * dt * dt;
  motion.velocity_by_bias = Eigen::Matrix3d::Identity() * dt;
  motion.position_by_bias = Eigen::Matrix3d::Identity() * 0.5 * dt * dt;
  const Eigen::Vector3d impulse(0.0, 0.5, 0.0);  // m/s, at dt / 2
  Preintegration aliased = motion;
  aliased.velocity += impulse;
  aliased.position += impulse * 0.5 * dt;
  const Eigen::Matrix3d attitude = Eigen::Matrix3d::Identity();

  InertialFilter filter(config);
  GatedDrive drive;
  Eigen::Vector3d velocity(2.0, 0.0, 0.0);
  Eigen::Vector3d last_translation = velocity * dt;
  for (int scan = 0; scan < 30; ++scan) {
    Eigen::Isometry3d registered = Eigen::Isometry3d::Identity();
    registered.translation() = velocity * dt + 0.5 * acceleration * dt * dt;
    if (scan >= 2 && !filter.ready()) drive.not_ready.push_back(scan);
    if (scan > impulse_scan && filter.ready()) {
      const Eigen::Vector3d prior = filter.predictTranslation(motion, attitude, Eigen::Matrix3d::Identity());
      drive.worst_after_impulse = std::max(drive.worst_after_impulse, (prior - registered.translation()).norm());
    }
    if (!filter.update(scan == impulse_scan ? aliased : motion, attitude, registered, last_translation)) {
      drive.gated.push_back(scan);
    }
    last_translation = registered.translation();
    velocity += acceleration * dt;
  }
  return drive;
}

TEST(InertialFilter, AConsistentForcePassesTheGateAndAnImpulseIsGated) {
  const ImuConfig config = mountedUpsideDownAndTurned();
  const GatedDrive consistent = driveWithAnImpulse(config, -1);
  EXPECT_TRUE(consistent.gated.empty());
  EXPECT_TRUE(consistent.not_ready.empty());

  const GatedDrive impulse = driveWithAnImpulse(config, 20);
  EXPECT_EQ(impulse.gated, std::vector<int>({20}));
  EXPECT_EQ(impulse.not_ready, std::vector<int>({21, 22}));  // on the LiDAR-only prior
  EXPECT_LT(impulse.worst_after_impulse, 1e-2);

  ImuConfig ungated = config;
  ungated.accel_gate = 1e3;
  const GatedDrive misled = driveWithAnImpulse(ungated, 20);
  EXPECT_TRUE(misled.gated.empty());
  EXPECT_GT(misled.worst_after_impulse, 2e-2);
}

}  // namespace
}  // namespace elo
