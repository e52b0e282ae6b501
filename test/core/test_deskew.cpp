// Motion compensation (docs/deskew.md): the per-point SE(3) math, the azimuth times, the deskewed
// projection of a sweep taken while moving, bad per-point times, and the odometry on such sweeps.
#include <gtest/gtest.h>

#include <cstdio>
#include <cstring>
#include <limits>
#include <random>
#include <string>

#include "analytic_scene.hpp"
#include "core/common/deskew.hpp"
#include "core/common/eigen_interop.hpp"
#include "core/cpu/deskew_lanes.hpp"
#include "core/cpu/stages.hpp"
#include "elo/imu/imu_track.hpp"
#include "elo/pipeline/deskew.hpp"
#include "elo/pipeline/odometry.hpp"

namespace elo {
namespace {

// A car at 10 m/s turning at 0.5 rad/s, bouncing a little: a 1 m seam at the ends of a sweep.
Vector6d drivingVelocity() {
  Vector6d velocity;
  velocity << 10.0, 0.3, 0.05, 0.02, -0.03, 0.5;
  return velocity;
}

TEST(Deskew, PointMathIsTheSe3ExponentialInFloat) {
  // Rotations from none to beyond the series' half radian, on points out to 100 m.
  const double rates[] = {0.0, 1e-4, 0.5, 4.0, 12.0};
  for (double rate : rates) {
    Vector6d velocity;
    velocity << 12.0, -3.0, 0.5, 0.3 * rate, -0.2 * rate, rate;
    for (float time : {-0.1f, -0.05f, 0.013f, 0.1f}) {
      const Eigen::Isometry3d exact = expSE3(static_cast<double>(time) * velocity);
      for (const Eigen::Vector3d& p : {Eigen::Vector3d(100, 0, 0), Eigen::Vector3d(-3, 40, -1.7),
                                      Eigen::Vector3d(0.5, -0.5, 8)}) {
        const Float3 moved = deskewPoint(toSweepVelocity(velocity), time, toFloat3(p.cast<float>()));
        const Eigen::Vector3d expected = exact * p;
        // Float rounding: a few ulps of the 100 m point.
        EXPECT_LT((Eigen::Vector3d(moved.x, moved.y, moved.z) - expected).norm(), 4e-5)
            << "rate " << rate << ", time " << time;
        const Float3 turned = deskewDirection(toSweepVelocity(velocity), time, {0.0f, 0.6f, 0.8f});
        EXPECT_LT((Eigen::Vector3d(turned.x, turned.y, turned.z) - exact.linear() * Eigen::Vector3d(0, 0.6, 0.8)).norm(),
                  1e-6);
      }
    }
  }
}

TEST(Deskew, SweepVelocityInterpolatesTheIncrementOnSe3) {
  const Eigen::Isometry3d increment = test::pose(1.0, 0.1, -0.02, 0.5, -0.3, 4.0);
  const Vector6d velocity = sweepVelocity(increment, 0.1);
  // At the full interval the constant twist is the increment; halfway it is the geodesic's midpoint.
  EXPECT_TRUE(expSE3(0.1 * velocity).isApprox(increment, 1e-12));
  const Eigen::Isometry3d half = expSE3(0.05 * velocity);
  EXPECT_TRUE((half * half).isApprox(increment, 1e-12));
  EXPECT_EQ(sweepVelocity(increment, 0.0), Vector6d::Zero());
}

TEST(Deskew, ARoundRunsWhenTheNewMotionMovesTheSweepsEndsByMoreThanAConvergedStep) {
  const RegistrationConfig config;  // 0.5 mm, 5e-5 rad
  const Vector6d velocity = drivingVelocity();
  EXPECT_FALSE(changesRegistration(velocity, velocity, 0.05, config));
  Vector6d faster = velocity;
  faster(0) += 0.009;  // 0.45 mm over 50 ms
  EXPECT_FALSE(changesRegistration(velocity, faster, 0.05, config));
  faster(0) += 0.002;  // 0.55 mm
  EXPECT_TRUE(changesRegistration(velocity, faster, 0.05, config));
  Vector6d turning = velocity;
  turning(5) += 0.0011;  // 5.5e-5 rad over 50 ms
  EXPECT_TRUE(changesRegistration(velocity, turning, 0.05, config));
  EXPECT_FALSE(changesRegistration(velocity, turning, 0.04, config));
}

TEST(Deskew, AzimuthTimesFollowKittisConvention) {
  const SweepTiming kitti = SweepTiming::fromConfig(SensorConfig(), TimeSource::azimuth);
  // 0.5 (1 - atan2(y, x) / pi) of a 0.1 s sweep, relative to mid-sweep (facing forward). fastAtan2 errs by
  // 1e-5 rad: 2e-7 s.
  constexpr float kTolerance = 3e-7f;
  EXPECT_NEAR(kitti.azimuthTime({10, 0, 0}), 0.0f, kTolerance);
  EXPECT_NEAR(kitti.azimuthTime({0, 10, 1}), -0.025f, kTolerance);  // left: a quarter in
  EXPECT_NEAR(kitti.azimuthTime({0, -10, 1}), 0.025f, kTolerance);  // right: three quarters
  EXPECT_NEAR(kitti.azimuthTime({-10, 1e-5f, 0}), -0.05f, kTolerance);  // just after the start, behind
  EXPECT_NEAR(kitti.azimuthTime({-10, -1e-5f, 0}), 0.05f, kTolerance);  // just before the end
  for (int i = 0; i < 100; ++i) {
    const double azimuth = -M_PI + 2.0 * M_PI * (i + 0.37) / 100.0;
    const Float3 p{static_cast<float>(20 * std::cos(azimuth)), static_cast<float>(20 * std::sin(azimuth)), -1.0f};
    const double kiss_icp = 0.5 * (-std::atan2(p.y, p.x) / M_PI + 1.0);
    EXPECT_NEAR(kitti.azimuthTime(p), (kiss_icp - 0.5) * 0.1, kTolerance) << azimuth;
  }
  // Counter-clockwise at 20 Hz from straight ahead: the left is a quarter in, the back mid-sweep.
  SensorConfig sensor;
  sensor.clockwise = false;
  sensor.sweep_start_azimuth_deg = 0.0;
  sensor.rotation_rate_hz = 20.0;
  const SweepTiming other = SweepTiming::fromConfig(sensor, TimeSource::azimuth);
  EXPECT_NEAR(other.azimuthTime({0, 10, 0}), -0.0125f, kTolerance);
  EXPECT_NEAR(other.azimuthTime({-10, 0, 0}), 0.0f, kTolerance);
}

// The sweep of a moving sensor, deskewed, is what an instantaneous sensor at the reference pose sees:
// each vertex lies on the scene where a ray from the reference pose through it meets the scene.
// The CPU's pass over the pixels (a vectorised loop where every pixel turns little, the per-pixel
// function elsewhere) gives every pixel exactly what redeskewPixel() gives it, the function the CUDA
// kernel runs per pixel: on a scan turning little, one turning fast, and one whose third block holds
// points far enough from the reference to need the exact coefficients. Empty pixels, with a past scan's
// point and time left in them, stay empty, as does a block without points (the fourth).
// With times from the azimuth, the motion between two scans is measured over whole sweep periods: KITTI-raw
// stamps rounded to 10 ms (0.10 and 0.11 s apart) give the same interval, a dropped scan two periods.
TEST(Deskew, AzimuthMotionIntervalsAreWholeSweepPeriods) {
  SensorConfig sensor;  // 10 Hz
  EXPECT_DOUBLE_EQ(motionInterval(0.11, TimeSource::azimuth, sensor), 0.1);
  EXPECT_DOUBLE_EQ(motionInterval(0.09, TimeSource::azimuth, sensor), 0.1);
  EXPECT_DOUBLE_EQ(motionInterval(0.21, TimeSource::azimuth, sensor), 0.2);
  EXPECT_DOUBLE_EQ(motionInterval(0.01, TimeSource::azimuth, sensor), 0.1) << "at least one period";
  sensor.rotation_rate_hz = 20.0;
  EXPECT_DOUBLE_EQ(motionInterval(0.11, TimeSource::azimuth, sensor), 0.1);
  EXPECT_DOUBLE_EQ(motionInterval(0.11, TimeSource::field, sensor), 0.11) << "the driver's stamps are the sweeps'";
  EXPECT_DOUBLE_EQ(motionInterval(0.11, TimeSource::none, sensor), 0.11);
}

TEST(Deskew, TheCpuPassOverPixelsGivesEachPixelThePerPixelMath) {
  ScanImage before;
  before.resize(4, 1024);  // a block of the pass per row
  const size_t pixels = before.image.pixelCount();
  for (size_t pixel = 0; pixel < pixels; ++pixel) {
    const float x = 0.001f * static_cast<float>(pixel);
    before.measured[pixel] =
        Eigen::Vector3f(3.0f + 40.0f * std::sin(x), 30.0f * std::cos(1.3f * x), -1.7f + std::sin(7.0f * x));
    // Rows 0 and 1 within half a sweep of the reference; row 2 out to two sweeps, as `field` times may be.
    before.time[pixel] = (pixel < 2048 ? 0.05f : 0.2f) * std::sin(3.1f * x);
    before.image.vertex[pixel] = before.measured[pixel];
    const bool empty = pixel % 7 == 3 || pixel >= 3072;
    before.image.range[pixel] = empty ? 0.0f : before.measured[pixel].norm();
    const Eigen::Vector3f normal = Eigen::Vector3f(std::sin(x), std::cos(x), 0.3f).normalized();
    before.image.normal[pixel] = pixel % 5 == 0 || empty ? Eigen::Vector3f::Zero() : normal;
  }
  Vector6d fast_turn;
  fast_turn << 12.0, -3.0, 0.5, 3.6, -2.4, 12.0;
  const std::pair<Vector6d, Vector6d> cases[] = {{0.7 * drivingVelocity(), drivingVelocity()},
                                                 {drivingVelocity(), fast_turn}};
  for (const auto& [applied_twist, twist] : cases) {
    const SweepVelocity applied = toSweepVelocity(applied_twist);
    const SweepVelocity velocity = toSweepVelocity(twist);
    ScanImage scan = before;
    cpu::deskewScan(applied, velocity, scan);
    for (size_t pixel = 0; pixel < pixels; ++pixel) {
      if (!before.image.occupied(pixel)) {
        ASSERT_EQ(scan.image.range[pixel], 0.0f) << pixel;
        ASSERT_TRUE(scan.image.normal[pixel].isZero()) << pixel;
        ASSERT_EQ(scan.image.vertex[pixel], before.image.vertex[pixel]) << pixel;
        continue;
      }
      Float3 vertex;
      float range = 0.0f;
      Float3 normal = toFloat3(before.image.normal[pixel]);
      redeskewPixel(applied, velocity, toFloat3(before.measured[pixel]), before.time[pixel], vertex, range, normal);
      ASSERT_EQ(scan.image.vertex[pixel], toVec3f(vertex)) << pixel;
      ASSERT_EQ(scan.image.range[pixel], range) << pixel;
      ASSERT_EQ(scan.image.normal[pixel], toVec3f(normal)) << pixel;
    }
  }
}

#ifdef ELO_PIXEL_LANES
// The projection places a cloud's points 8 at a time where all of a group's turn little
// (deskew_lanes.hpp): each lane gets scanPointVertex()'s measured point, time and vertex, bit for bit,
// and the lanes with a point are the points scanPointVertex() places (finite, with a time of the sweep).
// Times from a field (some outside the sweep, some NaN) and from the azimuth, with and without KITTI's
// elevation correction, at rest, driving, in a sharp turn, which sends the groups that hold a point
// more than 40 ms from the reference back to placing point by point, and swung with a gyro's rotation
// (times in lanes, each point turned by the shared function).
TEST(Deskew, PointsPlacedEightAtOnceAreThoseOfTheSharedMath) {
  constexpr size_t kGroups = 2000;
  constexpr size_t kPoints = kGroups * cpu::kPixelLanes;
  std::mt19937 random(7);
  std::uniform_real_distribution<float> across(-60.0f, 60.0f);
  std::uniform_real_distribution<float> height(-3.0f, 3.0f);
  std::uniform_real_distribution<float> within_sweep(-0.06f, 0.06f);
  std::vector<float> xyz;
  std::vector<float> times;
  for (size_t i = 0; i < kPoints; ++i) {
    xyz.insert(xyz.end(), {i % 97 == 5 ? NAN : across(random), across(random), height(random)});
    times.push_back(i % 89 == 7 ? 5.0f : i % 101 == 3 ? NAN : within_sweep(random));
  }
  Vector6d sharp_turn;  // turning little only within 40 ms of the reference
  sharp_turn << 8.0, 0.0, 0.0, 0.0, 0.0, 0.8;
  // Swung at 180 deg/s, the rate rising by half within the sweep, turned by a gyro's rotation.
  Vector6d swung;
  swung << 1.4, 0.0, 0.0, 0.0, 0.0, M_PI;
  ImuTrack gyro{ImuConfig()};
  for (int i = -40; i <= 40; ++i) {
    ImuSample sample;
    sample.stamp = 0.005 * i;
    sample.angular_velocity = Eigen::Vector3d(0.0, 0.0, M_PI + 5.0 * M_PI * sample.stamp);
    gyro.add(sample);
  }
  GyroSweep swing;
  ASSERT_EQ(gyro.sweepRotation(0.0, -0.05, 0.05, swing), "");
  SensorConfig sensor;
  for (const double correction_deg : {0.0, 0.195}) {
    sensor.elevation_correction_deg = correction_deg;
    const ElevationCorrection correction = ElevationCorrection::fromConfig(sensor);
    for (const TimeSource source : {TimeSource::field, TimeSource::azimuth}) {
      for (const Vector6d& twist : {Vector6d::Zero().eval(), drivingVelocity(), sharp_turn, swung}) {
        const bool turns_sharply = twist == sharp_turn;
        SCOPED_TRACE(std::string(source == TimeSource::field ? "field" : "azimuth") + " times, correction " +
                     std::to_string(correction_deg) +
                     (turns_sharply ? ", sharp turn" : twist == swung ? ", swung" : twist.isZero() ? ", at rest" : ""));
        SweepDeskew deskew{SweepTiming::fromConfig(sensor, source),
                           source == TimeSource::field ? times.data() : nullptr, toSweepVelocity(twist)};
        if (twist == swung) deskew.rotation = toSweepRotation(swing);
        std::vector<ScanPoint> placed(kPoints);
        size_t groups_in_lanes = 0;
        size_t points_placed = 0;
        for (size_t first = 0; first < kPoints; first += cpu::kPixelLanes) {
          cpu::PlacedLanes lanes;
          if (!cpu::placeLanes(correction, deskew, xyz.data(), first, placed.data(), lanes)) continue;
          ++groups_in_lanes;
          float vertex[3][cpu::kPixelLanes];
          _mm256_storeu_ps(vertex[0], lanes.x);
          _mm256_storeu_ps(vertex[1], lanes.y);
          _mm256_storeu_ps(vertex[2], lanes.z);
          for (int lane = 0; lane < cpu::kPixelLanes; ++lane) {
            const size_t i = first + lane;
            const Float3 raw{xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]};
            ScanPoint expected;
            const bool has_point = isFinite(raw) && scanPointVertex(correction, deskew, static_cast<int>(i), raw, expected);
            ASSERT_EQ((lanes.usable >> lane) & 1u, has_point ? 1u : 0u) << "point " << i;
            if (!has_point) continue;
            ++points_placed;
            const Float3 lane_vertex{vertex[0][lane], vertex[1][lane], vertex[2][lane]};
            ASSERT_EQ(std::memcmp(&placed[i].measured, &expected.measured, sizeof(Float3)), 0) << "point " << i;
            ASSERT_EQ(std::memcmp(&placed[i].vertex, &expected.vertex, sizeof(Float3)), 0) << "point " << i;
            ASSERT_EQ(std::memcmp(&lane_vertex, &expected.vertex, sizeof(Float3)), 0) << "point " << i;
            ASSERT_EQ(std::memcmp(&placed[i].time, &expected.time, sizeof(float)), 0) << "point " << i;
          }
        }
        if (turns_sharply) {
          EXPECT_GT(groups_in_lanes, 0u);
          EXPECT_LT(groups_in_lanes, kGroups / 2);
        } else {
          EXPECT_EQ(groups_in_lanes, kGroups);
        }
        EXPECT_GT(points_placed, groups_in_lanes * cpu::kPixelLanes * 9 / 10);
      }
    }
  }
}
#endif

class MovingSweep : public ::testing::TestWithParam<TimeSource> {
 protected:
  void SetUp() override {
    config_.runtime.threads = 2;
    config_.deskew.time_source = GetParam();
    truth_ = test::sweepScene(scene_, config_.sensor, reference_, drivingVelocity());
    truth_.cloud.ring.clear();
    if (GetParam() == TimeSource::azimuth) truth_.cloud.time.clear();
    backend_ = makeBackend(config_);
  }

  // The share of the pixels farther than 0.3 m from an edge whose vertex lies on the scene, within
  // `tolerance`, along its ray from the reference pose. (An instantaneous sensor sees the other side of
  // an edge, and behind a pole what the moving one saw around it: a few pixels.)
  double shareOnTheScene(double tolerance) {
    const ScanImage& scan = backend_->scan();
    size_t checked = 0;
    size_t on_scene = 0;
    for (size_t pixel = 0; pixel < scan.image.pixelCount(); ++pixel) {
      if (!scan.image.occupied(pixel) || truth_.edge_distance[scan.point_index[pixel]] < 0.3) continue;
      const Eigen::Vector3d vertex = scan.image.vertex[pixel].cast<double>();
      const test::Hit hit = scene_.cast(reference_.translation(), reference_.linear() * vertex.normalized());
      on_scene += std::abs(hit.range - vertex.norm()) < tolerance;
      ++checked;
    }
    EXPECT_GT(checked, 50000u);
    return static_cast<double>(on_scene) / checked;
  }

  Config config_;
  const test::Scene scene_ = test::streetScene();
  const Eigen::Isometry3d reference_ = test::pose(-5, 0.5, 0, 0, 0, 10);
  test::ScanWithTruth truth_;
  std::unique_ptr<Backend> backend_;
};

TEST_P(MovingSweep, DeskewedWithTheTrueMotionEqualsTheInstantaneousScan) {
  backend_->projectScan(truth_.cloud, 0.0f, {GetParam(), drivingVelocity()});
  // Float precision at up to 60 m (azimuth times: fastAtan2's 2e-7 s more, 2 um at 10 m/s).
  EXPECT_GT(shareOnTheScene(2e-4), 0.99);
  backend_->projectScan(truth_.cloud, 0.0f, {GetParam(), Vector6d::Zero()});
  EXPECT_LT(shareOnTheScene(0.01), 0.5);  // as measured: bent by the motion
}

TEST_P(MovingSweep, DeskewingAgainInPlaceEqualsDeskewingInTheProjection) {
  backend_->projectScan(truth_.cloud, 0.0f, {GetParam(), drivingVelocity()});
  backend_->segmentGround();
  backend_->estimateNormals();
  const ScanImage direct = backend_->scan();

  Vector6d prior = 0.7 * drivingVelocity();  // a prior 30% off
  backend_->projectScan(truth_.cloud, 0.0f, {GetParam(), prior});
  backend_->segmentGround();
  backend_->estimateNormals();
  backend_->deskewScan(drivingVelocity());
  EXPECT_GT(shareOnTheScene(2e-4), 0.99);
  const ScanImage& again = backend_->scan();
  // The same cloud point, wherever each projection put it (the prior's deskew moved some to other pixels).
  std::vector<int32_t> direct_pixel(truth_.cloud.size(), -1);
  for (size_t pixel = 0; pixel < direct.image.pixelCount(); ++pixel) {
    if (direct.image.occupied(pixel)) direct_pixel[direct.point_index[pixel]] = static_cast<int32_t>(pixel);
  }
  size_t compared = 0;
  size_t normals_compared = 0;
  for (size_t pixel = 0; pixel < again.image.pixelCount(); ++pixel) {
    if (!again.image.occupied(pixel)) continue;
    const int32_t point = again.point_index[pixel];
    const int32_t other = direct_pixel[point];
    if (other < 0) continue;
    ++compared;
    EXPECT_LT((again.image.vertex[pixel] - direct.image.vertex[other]).norm(), 1e-5f);
    // The normal turned with its window agrees with the one estimated on the deskewed window.
    if (again.image.hasNormal(pixel) && direct.image.hasNormal(other) && truth_.edge_distance[point] > 0.5) {
      EXPECT_GT(std::abs(again.image.normal[pixel].dot(direct.image.normal[other])), std::cos(0.5 * M_PI / 180.0));
      EXPECT_NEAR(again.image.normal[pixel].norm(), 1.0f, 1e-6f);
      ++normals_compared;
    }
  }
  EXPECT_GT(compared, 60000u);
  EXPECT_GT(normals_compared, 20000u);
}

INSTANTIATE_TEST_SUITE_P(BothTimeSources, MovingSweep, ::testing::Values(TimeSource::field, TimeSource::azimuth));

// A sensor swung about a fixed, tilted axis at 180 deg/s at mid-sweep, the rate rising linearly by half of
// that over the sweep, at its reference position: with a gyro (docs/imu.md) each point is turned by the
// rotation at its own time.
class SweepTurningFaster : public ::testing::TestWithParam<TimeSource> {
 protected:
  static constexpr double kRate = M_PI;                // rad/s at mid-sweep
  static constexpr double kRateChange = 0.5 * M_PI / 0.1;  // rad/s^2

  static double angleAt(double time) { return kRate * time + 0.5 * kRateChange * time * time; }

  void SetUp() override {
    config_.runtime.threads = 2;
    truth_ = test::swungSweepScene(test::streetScene(), config_.sensor, reference_, swing_);
    truth_.cloud.ring.clear();
    if (GetParam() == TimeSource::azimuth) truth_.cloud.time.clear();
    // A 200 Hz gyro mounted upside down and turned a quarter: its rates in its own axes.
    ImuConfig imu;
    imu.rotation_deg = {180.0, 0.0, 90.0};
    track_ = std::make_unique<ImuTrack>(imu);
    const Eigen::Matrix3d imu_from_lidar = lidarFromImuRotation(imu).transpose();
    for (int i = -40; i <= 40; ++i) {
      ImuSample sample;
      sample.stamp = 0.005 * i;
      sample.angular_velocity = imu_from_lidar * swing_.axis * (kRate + kRateChange * sample.stamp);
      ASSERT_EQ(track_->add(sample), "");
    }
    backend_ = makeBackend(config_);
  }

  // The largest distance of a deskewed vertex from its point's true place, over the range.
  double worstRelativeError() {
    const ScanImage& scan = backend_->scan();
    double worst = 0.0;
    size_t checked = 0;
    for (size_t pixel = 0; pixel < scan.image.pixelCount(); ++pixel) {
      if (!scan.image.occupied(pixel)) continue;
      const int32_t point = scan.point_index[pixel];
      const Eigen::Vector3d measured = truth_.cloud.points[point].cast<double>();
      const Eigen::Vector3d truth = swing_.at(test::firingTime(config_.sensor, truth_.step[point])) * measured;
      worst = std::max(worst, (scan.image.vertex[pixel].cast<double>() - truth).norm() / measured.norm());
      ++checked;
    }
    EXPECT_GT(checked, 50000u);
    return worst;
  }

  Config config_;
  const Eigen::Isometry3d reference_ = test::pose(-5, 0.5, 0, 0, 0, 10);
  const test::Swing<double (*)(double)> swing_{Eigen::Vector3d(0.1, -0.2, 1.0).normalized(), &angleAt,
                                               Eigen::Vector3d::Zero()};
  test::ScanWithTruth truth_;
  std::unique_ptr<ImuTrack> track_;
  std::unique_ptr<Backend> backend_;
};

TEST_P(SweepTurningFaster, TheGyroRecoversEveryPointToFloatPrecisionWhereItsMeanRateDoesNot) {
  const GyroMotion gyro = track_->scanMotion(-0.1, 0.0, -0.05, 0.05, 0.0);
  ASSERT_TRUE(gyro.known) << gyro.fallback;
  ASSERT_TRUE(gyro.sweep.known());
  Vector6d mean_rate = Vector6d::Zero();
  mean_rate.tail<3>() = gyro.sweep_rate;

  backend_->projectScan(truth_.cloud, 0.0f, {GetParam(), mean_rate, 0.0, gyro.sweep});
  // Float precision (azimuth times: fastAtan2's 2e-7 s more, 6e-7 rad at this rate).
  const double per_point = worstRelativeError();
  EXPECT_LT(per_point, GetParam() == TimeSource::field ? 1e-6 : 2e-6);
  backend_->segmentGround();
  backend_->estimateNormals();
  const ScanImage projected = backend_->scan();

  // The registration's rounds move the points by a new translation; the gyro's turn stays, and so do the
  // normals, bit for bit. Without a translation, the vertices stay too.
  backend_->deskewScan(mean_rate);
  EXPECT_EQ(backend_->scan().image.vertex, projected.image.vertex);
  EXPECT_EQ(backend_->scan().image.normal, projected.image.normal);
  Vector6d moving = mean_rate;
  moving.head<3>() << 1.4, 0.2, 0.0;
  backend_->deskewScan(moving);
  EXPECT_EQ(backend_->scan().image.normal, projected.image.normal);
  EXPECT_GT(worstRelativeError(), 1e-3);  // 7 cm at the sweep's ends

  // At the gyro's mean rate over the sweep (a constant twist), the ends are turned by about 1.1 deg too
  // little: 1.9e-2 of their range.
  backend_->projectScan(truth_.cloud, 0.0f, {GetParam(), mean_rate});
  const double mean = worstRelativeError();
  std::printf("[ gyro deskew ] worst error over range: per point %.2g, at the mean rate %.2g\n", per_point, mean);
  EXPECT_GT(mean, 1e-2);
}

INSTANTIATE_TEST_SUITE_P(BothTimeSources, SweepTurningFaster,
                         ::testing::Values(TimeSource::field, TimeSource::azimuth));

// Bad per-point times: taken as instantaneous, or the bad points dropped, always with a counted warning.
TEST(DeskewTimes, UnusableTimesAreReportedAndNeverUsed) {
  Config config;
  PointCloud cloud = test::sweepScene(test::streetScene(), config.sensor, Eigen::Isometry3d::Identity(),
                                      drivingVelocity())
                         .cloud;
  EXPECT_EQ(inspectTimes(cloud, config).source, TimeSource::field);
  EXPECT_TRUE(inspectTimes(cloud, config).warning.empty());

  const auto check = [&](PointCloud bad, const std::string& warning) {
    const CloudTimes times = inspectTimes(bad, config);
    EXPECT_EQ(times.source, TimeSource::none) << warning;
    EXPECT_NE(times.warning.find(warning), std::string::npos) << times.warning;
  };
  PointCloud no_times = cloud;
  no_times.time.clear();
  check(no_times, "no per-point times");
  PointCloud short_times = cloud;
  short_times.time.pop_back();
  check(short_times, "not one per-point time per point");
  PointCloud zeros = cloud;
  std::fill(zeros.time.begin(), zeros.time.end(), 0.0f);
  check(zeros, "all equal");
  PointCloud milliseconds = cloud;  // a driver's unit mistaken: -50 .. 50 "seconds"
  for (float& time : milliseconds.time) time *= 1000.0f;
  check(milliseconds, "mostly outside the sweep");

  config.deskew.time_source = TimeSource::azimuth;  // the cloud's times are not looked at
  EXPECT_EQ(inspectTimes(zeros, config).source, TimeSource::azimuth);
  EXPECT_TRUE(inspectTimes(zeros, config).warning.empty());
}

TEST(DeskewTimes, PointsWithATimeOutsideTheSweepAreDroppedAndCounted) {
  Config config;
  config.runtime.threads = 2;
  const test::ScanWithTruth truth =
      test::sweepScene(test::streetScene(), config.sensor, Eigen::Isometry3d::Identity(), drivingVelocity());
  PointCloud bad = truth.cloud;
  PointCloud without = truth.cloud;
  without.points.clear();
  without.time.clear();
  without.ring.clear();
  const float broken[] = {std::numeric_limits<float>::quiet_NaN(), std::numeric_limits<float>::infinity(), 1e9f,
                          -0.21f};
  for (size_t i = 0; i < bad.size(); ++i) {
    if (i % 97 == 0) {
      bad.time[i] = broken[(i / 97) % 4];
    } else {
      without.points.push_back(bad.points[i]);
      without.time.push_back(bad.time[i]);
      without.ring.push_back(bad.ring[i]);
    }
  }
  const CloudTimes times = inspectTimes(bad, config);
  EXPECT_EQ(times.source, TimeSource::field);
  EXPECT_EQ(times.outside_sweep, bad.size() - without.size());
  EXPECT_NE(times.warning.find("dropped"), std::string::npos);
  // The projection drops exactly those points: the same image as the cloud without them.
  const auto project = [&](const PointCloud& cloud) {
    std::unique_ptr<Backend> backend = makeBackend(config);
    backend->projectScan(cloud, 0.0f, {TimeSource::field, drivingVelocity()});
    return backend->scan().image;
  };
  const SphericalImage from_bad = project(bad);
  const SphericalImage from_good = project(without);
  EXPECT_EQ(from_bad.range, from_good.range);
  EXPECT_EQ(from_bad.vertex, from_good.vertex);

  Odometry odometry(config);
  const FrameResult result = odometry.process(bad);
  EXPECT_TRUE(result.processed);
  EXPECT_EQ(result.points_without_time, times.outside_sweep);
  EXPECT_EQ(odometry.timeWarningCounts().at(times.warning), 1u);
}

// A drive at 10 m/s, turning: deskewed (by either time source) the odometry tracks the truth as on
// instantaneous scans; as measured it drifts. The second scan registers against the first as measured
// (nothing is known of the motion before), exactly as without deskew, 8 mm off the truth; then both are
// deskewed under the motion found and registered again, within a millimetre.
struct DriveError {
  double second_scan_mm = 0.0;  // translation error of the second scan
  double drift_mm = 0.0;        // the largest translation error after it, relative to it
  double drift_deg = 0.0;
};

// `stamp_before_mid`: the clouds are stamped this long before mid-sweep, their times counted from the
// stamp (half a period: the sweep's start, as Velodyne drivers stamp it). At a constant velocity the
// truth between stamps is the truth between mid-sweeps.
DriveError driveError(TimeSource source, RegistrationMode mode, bool moving_sweeps, double stamp_before_mid = 0.0) {
  Config config;
  config.runtime.threads = 2;
  config.deskew.time_source = source;
  config.model.mode = mode;
  Odometry odometry(config);
  const test::Scene scene = test::streetScene();
  const Eigen::Isometry3d start = test::pose(-25, 0, 0, 0, 0, 0);
  const double period = 0.1;
  Vector6d velocity;
  velocity << 10.0, 0.0, 0.0, 0.0, 0.0, 0.12;
  DriveError error;
  Eigen::Isometry3d second_pose = Eigen::Isometry3d::Identity();
  for (int frame = 0; frame < 10; ++frame) {
    const Eigen::Isometry3d truth = expSE3(frame * period * velocity);
    PointCloud cloud = moving_sweeps ? test::sweepScene(scene, config.sensor, start * truth, velocity, frame * period).cloud
                                     : test::scanScene(scene, config.sensor, start * truth, frame * period).cloud;
    cloud.ring.clear();
    if (source == TimeSource::azimuth) cloud.time.clear();
    for (float& time : cloud.time) time += static_cast<float>(stamp_before_mid);
    const FrameResult result = odometry.process(cloud);
    EXPECT_TRUE(result.processed) << result.skip_reason;
    // The second scan is deskewed under its registered motion; later ones only while the prior was off.
    const bool deskewed = source != TimeSource::none && moving_sweeps;
    if (frame == 1 && deskewed) {
      EXPECT_EQ(result.deskew_rounds, 1);
    }
    EXPECT_LE(result.deskew_rounds, deskewed ? 1 : 0) << frame;
    if (frame == 1) {
      second_pose = result.pose;
      error.second_scan_mm = (truth.inverse() * result.pose).translation().norm() * 1000.0;
    } else if (frame > 1) {
      const Eigen::Isometry3d truth_since = expSE3(period * velocity).inverse() * truth;
      const Eigen::Isometry3d drift = truth_since.inverse() * second_pose.inverse() * result.pose;
      error.drift_mm = std::max(error.drift_mm, drift.translation().norm() * 1000.0);
      error.drift_deg = std::max(error.drift_deg, rotationAngle(drift) * 180.0 / M_PI);
    }
  }
  return error;
}

class DeskewedDrive : public ::testing::TestWithParam<RegistrationMode> {};

TEST_P(DeskewedDrive, TracksAsOnInstantaneousScans) {
  const DriveError instantaneous = driveError(TimeSource::none, GetParam(), false);
  const DriveError distorted = driveError(TimeSource::none, GetParam(), true);
  std::printf("drift after the second scan (mm / deg): instantaneous %.1f / %.3f, distorted %.1f / %.3f\n",
              instantaneous.drift_mm, instantaneous.drift_deg, distorted.drift_mm, distorted.drift_deg);
  for (TimeSource source : {TimeSource::field, TimeSource::azimuth}) {
    const DriveError deskewed = driveError(source, GetParam(), true);
    std::printf("deskewed (%s): %.1f / %.3f; second scan %.2f mm, as measured %.2f mm\n",
                source == TimeSource::field ? "field" : "azimuth", deskewed.drift_mm, deskewed.drift_deg,
                deskewed.second_scan_mm, distorted.second_scan_mm);
    EXPECT_LT(deskewed.second_scan_mm, std::min(1.0, 0.05 * distorted.second_scan_mm));
    EXPECT_LT(deskewed.drift_mm, std::max(2.0 * instantaneous.drift_mm, 3.0));
    EXPECT_LT(deskewed.drift_deg, std::max(2.0 * instantaneous.drift_deg, 0.01));
    EXPECT_LT(deskewed.drift_mm, 0.1 * distorted.drift_mm);
  }
  // Stamped at the sweep's start, the scans are registered at mid-sweep all the same and reported at
  // their stamps, half a sweep before, under each scan's velocity. The first two scans' stamps are
  // placed under the motion their deskewed scans registered: under the bent scans' (8 mm off in 0.1 s)
  // every later pose was 4.4 / 3.7 mm off (f2m / f2f), now 0.6 / 0.5 mm as stamped mid-sweep.
  const DriveError from_start = driveError(TimeSource::field, GetParam(), true, 0.05);
  std::printf("deskewed (field, stamped at the sweep's start): %.1f / %.3f; second scan %.2f mm\n",
              from_start.drift_mm, from_start.drift_deg, from_start.second_scan_mm);
  EXPECT_LT(from_start.second_scan_mm, std::min(1.0, 0.05 * distorted.second_scan_mm));
  EXPECT_LT(from_start.drift_mm, std::max(2.0 * instantaneous.drift_mm, 3.0));
  EXPECT_LT(from_start.drift_deg, std::max(2.0 * instantaneous.drift_deg, 0.01));
}

INSTANTIATE_TEST_SUITE_P(BothModes, DeskewedDrive,
                         ::testing::Values(RegistrationMode::frame_to_model, RegistrationMode::frame_to_frame));

}  // namespace
}  // namespace elo
