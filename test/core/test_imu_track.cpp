// The IMU's samples as the odometry reads them (docs/imu.md): the gyro integrated into the LiDAR's
// rotation through the mount, exactly on analytic rates; the checks that drop a sample or refuse an
// interval, each under its counted reason.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "elo/imu/imu_track.hpp"

namespace elo {
namespace {

constexpr double kRate = 200.0;  // Hz

ImuSample sampleAt(double stamp, const Eigen::Vector3d& rate) {
  ImuSample sample;
  sample.stamp = stamp;
  sample.angular_velocity = rate;
  sample.specific_force = Eigen::Vector3d(0.0, 0.0, 9.81);
  return sample;
}

// Samples of `rate(t)` every 1 / kRate s over [from, to].
template <typename Rate>
void feed(ImuTrack& track, double from, double to, const Rate& rate) {
  for (int i = 0; from + i / kRate <= to + 1e-12; ++i) {
    const double t = from + i / kRate;
    ASSERT_EQ(track.add(sampleAt(t, rate(t))), "");
  }
}

ImuConfig mountedUpsideDownAndTurned() {
  ImuConfig config;
  config.rotation_deg = {180.0, 0.0, 90.0};
  return config;
}

double angleBetween(const Eigen::Matrix3d& a, const Eigen::Matrix3d& b) {
  return Eigen::AngleAxisd(a.transpose() * b).angle();
}

// 1 rad/s about the IMU's z, which is the LiDAR's -z (upside down): the LiDAR turns clockwise.
TEST(ImuTrack, AConstantRateTurnsTheLidarThroughTheMount) {
  const ImuConfig config = mountedUpsideDownAndTurned();
  ImuTrack track(config);
  feed(track, 0.0, 1.0, [](double) { return Eigen::Vector3d(0.0, 0.0, 1.0); });
  Eigen::Matrix3d rotation;
  ASSERT_EQ(track.rotation(0.1234, 0.6234, rotation), "");
  const Eigen::Matrix3d expected = Eigen::AngleAxisd(-0.5, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  EXPECT_LT(angleBetween(rotation, expected), 1e-12);
  const GyroMotion motion = track.scanMotion(0.2, 0.3, 0.25, 0.35, 0.25);
  ASSERT_TRUE(motion.known) << motion.fallback;
  EXPECT_LT((motion.sweep_rate - Eigen::Vector3d(0.0, 0.0, -1.0)).norm(), 1e-12);
  // The stamp, at the sweep's start, 0.05 s before the reference: turned 0.05 rad anticlockwise from it.
  EXPECT_LT(angleBetween(motion.stamp_rotation, Eigen::AngleAxisd(0.05, Eigen::Vector3d::UnitZ()).toRotationMatrix()),
            1e-12);
  EXPECT_LT(angleBetween(track.scanMotion(0.2, 0.3, 0.25, 0.35, 0.35).stamp_rotation,
                         Eigen::AngleAxisd(-0.05, Eigen::Vector3d::UnitZ()).toRotationMatrix()),
            1e-12);
  // A stamp beyond the samples (which end at 1 s): the sweep's mean rate.
  const GyroMotion late = track.scanMotion(0.8, 0.9, 0.85, 0.95, 1.2);
  ASSERT_TRUE(late.known) << late.fallback;
  EXPECT_LT(angleBetween(late.stamp_rotation, Eigen::AngleAxisd(-0.3, Eigen::Vector3d::UnitZ()).toRotationMatrix()),
            1e-12);
}

// A rate rising linearly is integrated exactly between and within samples: 0.5 a t^2 about x.
TEST(ImuTrack, ARateLinearInTimeIsIntegratedExactly) {
  ImuTrack track{ImuConfig()};
  feed(track, 0.0, 1.0, [](double t) { return Eigen::Vector3d(2.0 * t, 0.0, 0.0); });
  Eigen::Matrix3d rotation;
  ASSERT_EQ(track.rotation(0.0013, 0.7021, rotation), "");
  const double angle = 0.7021 * 0.7021 - 0.0013 * 0.0013;
  EXPECT_LT(angleBetween(rotation, Eigen::AngleAxisd(angle, Eigen::Vector3d::UnitX()).toRotationMatrix()), 1e-12);
}

TEST(ImuTrack, TheBiasAndTheTimeOffsetAreApplied) {
  ImuConfig config;
  config.gyro_bias = {0.0, 0.0, 0.02};
  config.time_offset = -100.0;  // the IMU's clock runs 100 s ahead of the scans'
  ImuTrack track(config);
  feed(track, 100.0, 101.0, [](double) { return Eigen::Vector3d(0.0, 0.0, 0.52); });
  Eigen::Matrix3d rotation;
  ASSERT_EQ(track.rotation(0.0, 1.0, rotation), "");
  EXPECT_LT(angleBetween(rotation, Eigen::AngleAxisd(0.5, Eigen::Vector3d::UnitZ()).toRotationMatrix()), 1e-12);
}

TEST(ImuTrack, AnIntervalTheSamplesDoNotCoverOrAGapSaysWhy) {
  ImuTrack track{ImuConfig()};
  feed(track, 0.0, 0.5, [](double) { return Eigen::Vector3d(0.1, 0.0, 0.0); });
  feed(track, 0.55, 1.0, [](double) { return Eigen::Vector3d(0.1, 0.0, 0.0); });  // 50 ms without: over 2 / 50 Hz
  Eigen::Matrix3d rotation;
  EXPECT_EQ(track.rotation(0.9, 1.1, rotation), imu_issue::kNotCovered);
  EXPECT_EQ(track.rotation(-0.1, 0.2, rotation), imu_issue::kNotCovered);
  EXPECT_EQ(track.rotation(0.4, 0.6, rotation), imu_issue::kGap);
  EXPECT_EQ(track.rotation(0.6, 0.9, rotation), "");
  EXPECT_EQ(track.scanMotion(0.4, 0.6, 0.55, 0.65, 0.6).fallback, imu_issue::kGap);
}

TEST(ImuTrack, BadSamplesAreDroppedAndCounted) {
  ImuTrack track{ImuConfig()};
  ASSERT_EQ(track.add(sampleAt(1.0, Eigen::Vector3d::Zero())), "");
  EXPECT_EQ(track.add(sampleAt(1.005, Eigen::Vector3d(std::numeric_limits<double>::quiet_NaN(), 0.0, 0.0))),
            imu_issue::kNotFinite);
  EXPECT_EQ(track.add(sampleAt(1.01, Eigen::Vector3d(0.0, 40.0, 0.0))), imu_issue::kSaturated);  // 2292 deg/s
  EXPECT_EQ(track.add(sampleAt(0.995, Eigen::Vector3d::Zero())), imu_issue::kOutOfOrder);
  EXPECT_EQ(track.add(sampleAt(1.0, Eigen::Vector3d::Zero())), imu_issue::kOutOfOrder);
  EXPECT_EQ(track.size(), 1u);
  // Over a second back: a bag played again; the track starts over from the sample.
  EXPECT_EQ(track.add(sampleAt(-0.5, Eigen::Vector3d::Zero())), "");
  EXPECT_EQ(track.size(), 1u);
  const std::map<std::string, size_t> expected = {{imu_issue::kNotFinite, 1}, {imu_issue::kSaturated, 1},
                                                   {imu_issue::kOutOfOrder, 2}, {imu_issue::kClockJump, 1}};
  EXPECT_EQ(track.droppedCounts(), expected);
}

// A gyro reading 0.01 rad/s (0.6 deg/s) too high about the LiDAR's z, while the registrations say the LiDAR
// stood: within 3 s (30 scans) the estimate holds over three quarters of the bias, within 30 s all but 2 %.
TEST(ImuTrack, TheBiasIsLearntFromTheRegisteredRotations) {
  const ImuConfig config = mountedUpsideDownAndTurned();
  ImuTrack track(config);
  const Eigen::Vector3d bias_in_imu_axes(0.0, 0.0, -0.01);  // the IMU's z is the LiDAR's -z
  feed(track, 0.0, 30.0, [&](double) { return bias_in_imu_axes; });
  const auto learnt_share = [&] { return track.learntBias().dot(bias_in_imu_axes) / bias_in_imu_axes.squaredNorm(); };
  for (int scan = 1; scan <= 300; ++scan) {
    Eigen::Matrix3d gyro;
    ASSERT_EQ(track.rotation(0.1 * (scan - 1), 0.1 * scan, gyro), "");
    track.learnBias(gyro, Eigen::Matrix3d::Identity(), 0.1);
    if (scan == 30) {
      EXPECT_GT(learnt_share(), 0.75);
    }
  }
  EXPECT_NEAR(learnt_share(), 1.0, 0.02);
  EXPECT_LT((track.learntBias() - bias_in_imu_axes).norm(), 2e-4);
}

TEST(ImuTrack, ATimeConstantOfZeroKeepsTheBiasAsGiven) {
  ImuConfig config;
  config.bias_time_constant = 0.0;
  ImuTrack track(config);
  feed(track, 0.0, 1.0, [](double) { return Eigen::Vector3d(0.01, 0.0, 0.0); });
  Eigen::Matrix3d gyro;
  ASSERT_EQ(track.rotation(0.0, 0.1, gyro), "");
  track.learnBias(gyro, Eigen::Matrix3d::Identity(), 0.1);
  EXPECT_EQ(track.learntBias(), Eigen::Vector3d::Zero());
}

TEST(ImuTrack, OnlyTheSamplesAnIntervalStillNeedsAreKept) {
  ImuTrack track{ImuConfig()};
  feed(track, 0.0, 1.0, [](double) { return Eigen::Vector3d(0.0, 0.3, 0.0); });
  track.forgetBefore(0.5012);
  Eigen::Matrix3d rotation;
  EXPECT_EQ(track.rotation(0.5012, 0.9, rotation), "");
  EXPECT_EQ(track.rotation(0.49, 0.9, rotation), imu_issue::kNotCovered);
}

// The ROS node learns the mount from TF once running: the samples it already holds are read through the
// mount set then. Only the samples taken are counted; the bias estimate is the configured one and the learnt.
TEST(ImuTrack, AMountSetLaterTurnsTheSamplesHeldThroughIt) {
  ImuConfig config;
  config.gyro_bias = {0.001, 0.0, 0.0};
  ImuTrack track(config);
  feed(track, 0.0, 1.0, [](double) { return Eigen::Vector3d(0.001, 0.0, 1.0); });
  ImuSample not_finite = sampleAt(1.5, Eigen::Vector3d(0.0, 0.0, std::numeric_limits<double>::quiet_NaN()));
  EXPECT_EQ(track.add(not_finite), imu_issue::kNotFinite);
  EXPECT_EQ(track.takenCount(), 201u);
  track.setMount(mountedUpsideDownAndTurned());
  Eigen::Matrix3d rotation;
  ASSERT_EQ(track.rotation(0.2, 0.7, rotation), "");
  EXPECT_LT(angleBetween(rotation, Eigen::AngleAxisd(-0.5, Eigen::Vector3d::UnitZ()).toRotationMatrix()), 1e-12);
  EXPECT_EQ(track.biasEstimate(), Eigen::Vector3d(0.001, 0.0, 0.0));
}

}  // namespace
}  // namespace elo
