// The sensor on analytic scenes: exact ranges, beams, rings, times, range limits, noise, dropouts, clutter
// and per-laser calibration errors.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <numeric>

#include "elo/sim/ground.hpp"
#include "elo/sim/lidar.hpp"
#include "elo/sim/scene.hpp"
#include "elo/sim/sensors.hpp"
#include "sim_test_helpers.hpp"

namespace elo::sim {
namespace {

using test::azimuthOf;
using test::elevationsOf;
using test::exactOptions;
using test::exactSensor;
using test::stepOf;

constexpr double kSensorHeight = 1.73;

Eigen::Isometry3d atOrigin(double) { return Eigen::Isometry3d::Identity(); }

// A wall filling the half space x >= distance (thick, tall and wide enough for every forward beam).
Scene wallScene(double distance) {
  return Scene(nullptr, {{OrientedBox{Eigen::Vector3d(distance + 50.0, 0.0, 0.0), Eigen::Matrix3d::Identity(),
                                      Eigen::Vector3d(50.0, 1000.0, 1000.0)},
                          0.6f}});
}

double rangeOf(const PointCloud& cloud, size_t i) { return cloud.points[i].cast<double>().norm(); }

TEST(Lidar, FlatGroundRangesAreExact) {
  const SensorConfig sensor = exactSensor();
  const Lidar lidar(sensor, exactOptions());
  const Scene scene(std::make_shared<FlatGround>(-kSensorHeight), {});
  const SimulatedScan scan = lidar.sweep(scene, atOrigin, 0.0, 1);
  const std::vector<double> elevations = elevationsOf(sensor);

  std::vector<int> per_beam(lidar.beamCount(), 0);
  for (size_t i = 0; i < scan.cloud.size(); ++i) {
    const double elevation = elevations[scan.cloud.ring[i]];
    ASSERT_LT(elevation, 0.0) << "a beam at or above the horizon hit a flat ground";
    EXPECT_NEAR(rangeOf(scan.cloud, i), kSensorHeight / std::sin(-elevation), 2e-5);
    EXPECT_NEAR(scan.cloud.points[i].z(), -kSensorHeight, 1e-5);
    EXPECT_EQ(scan.surface[i], SurfaceKind::ground);
    ++per_beam[scan.cloud.ring[i]];
  }
  // Every beam below the horizon whose ground range lies within the sensor's limits returns at every step.
  for (int beam = 0; beam < lidar.beamCount(); ++beam) {
    const double range = elevations[beam] < 0.0 ? kSensorHeight / std::sin(-elevations[beam]) : INFINITY;
    const bool visible = range >= sensor.min_range && range <= sensor.max_range;
    EXPECT_EQ(per_beam[beam], visible ? lidar.azimuthSteps() : 0) << "beam " << beam;
  }
}

TEST(Lidar, WallRangesAreExact) {
  const SensorConfig sensor = exactSensor();
  const Lidar lidar(sensor, exactOptions());
  const double distance = 12.0;
  const SimulatedScan scan = lidar.sweep(wallScene(distance), atOrigin, 0.0, 1);
  const std::vector<double> elevations = elevationsOf(sensor);
  ASSERT_GT(scan.cloud.size(), 1000u);
  for (size_t i = 0; i < scan.cloud.size(); ++i) {
    const double azimuth = azimuthOf(lidar, stepOf(lidar, scan.cloud.points[i]));
    const double elevation = elevations[scan.cloud.ring[i]];
    EXPECT_NEAR(rangeOf(scan.cloud, i), distance / (std::cos(elevation) * std::cos(azimuth)), 2e-5);
    EXPECT_NEAR(scan.cloud.points[i].x(), distance, 1e-5);
  }
}

TEST(Lidar, RingAndOrderSanity) {
  const SensorConfig sensor = exactSensor();
  const Lidar lidar(sensor, exactOptions());
  const Scene scene(std::make_shared<FlatGround>(-kSensorHeight), {});
  const double stamp = 123.4;
  const SimulatedScan scan = lidar.sweep(scene, atOrigin, stamp, 1);
  EXPECT_EQ(scan.cloud.stamp, stamp);
  ASSERT_EQ(scan.cloud.ring.size(), scan.cloud.size());
  ASSERT_EQ(scan.cloud.intensity.size(), scan.cloud.size());
  // Taken at one instant: per-point times would only make a deskew move its points.
  EXPECT_TRUE(scan.cloud.time.empty());
  for (size_t i = 0; i < scan.cloud.size(); ++i) {
    EXPECT_LT(scan.cloud.ring[i], lidar.beamCount());
    EXPECT_GE(scan.cloud.intensity[i], 0.0f);
    EXPECT_LE(scan.cloud.intensity[i], 1.0f);
    // Each point lies exactly at a firing's azimuth, in firing order: clockwise from behind.
    const Eigen::Vector3f& p = scan.cloud.points[i];
    const int step = stepOf(lidar, p);
    EXPECT_NEAR(std::remainder(std::atan2(p.y(), p.x()) - azimuthOf(lidar, step), 2.0 * M_PI), 0.0, 1e-5);
    if (i > 0) {
      EXPECT_GE(step, stepOf(lidar, scan.cloud.points[i - 1])) << "points not in firing order";
    }
  }
}

TEST(Lidar, FieldTimesGrowClockwiseFromBehindFromTheStamp) {
  LidarOptions options = exactOptions();
  options.deskewed = false;
  options.time_convention = TimeConvention::field;
  const Lidar lidar(exactSensor(), options);
  const Scene scene(std::make_shared<FlatGround>(-kSensorHeight), {});
  const double start = 123.4;
  const SimulatedScan scan = lidar.sweep(scene, atOrigin, start, 1);
  EXPECT_EQ(lidar.referenceOffset(), 0.0);
  EXPECT_EQ(scan.cloud.stamp, start);
  ASSERT_EQ(scan.cloud.time.size(), scan.cloud.size());
  ASSERT_GT(scan.cloud.size(), 1000u);
  for (size_t i = 0; i < scan.cloud.size(); ++i) {
    EXPECT_GE(scan.cloud.time[i], 0.0f);
    EXPECT_LT(scan.cloud.time[i], lidar.sweepDuration());
    if (i > 0) {
      EXPECT_GE(scan.cloud.time[i], scan.cloud.time[i - 1]) << "points not in firing order";
    }
    // Time grows clockwise from behind: the azimuth of the point matches its firing step.
    const Eigen::Vector3f& p = scan.cloud.points[i];
    const double azimuth = azimuthOf(lidar, stepOf(lidar, scan.cloud.time[i]));
    EXPECT_NEAR(std::remainder(std::atan2(p.y(), p.x()) - azimuth, 2.0 * M_PI), 0.0, 1e-5);
  }
}

TEST(Lidar, NothingBeyondMaxRangeNorFromTheSky) {
  SensorConfig sensor = exactSensor();
  sensor.max_range = 30.0;
  sensor.range_noise_stddev = 0.05;  // noise must not push points past the limit either
  const Lidar lidar(sensor, exactOptions());
  // The ground reaches out to infinity and the wall stands beyond the range.
  const Scene scene(std::make_shared<FlatGround>(-kSensorHeight),
                    {{uprightBox(Eigen::Vector3d(60.0, 0.0, 0.0), Eigen::Vector3d(1.0, 200.0, 50.0), 0.0), 0.5f}});
  const SimulatedScan scan = lidar.sweep(scene, atOrigin, 0.0, 5);
  ASSERT_GT(scan.cloud.size(), 0u);
  const std::vector<double> elevations = elevationsOf(sensor);
  for (size_t i = 0; i < scan.cloud.size(); ++i) {
    EXPECT_LE(rangeOf(scan.cloud, i), sensor.max_range + 1e-4);
    EXPECT_GE(rangeOf(scan.cloud, i), sensor.min_range - 1e-4);
    EXPECT_LT(elevations[scan.cloud.ring[i]], 0.0);  // the beams above the horizon see only sky
  }
}

TEST(Lidar, RangeNoiseHasTheConfiguredSpread) {
  for (const double sigma : {0.02, 0.05}) {
    SensorConfig sensor = exactSensor();
    sensor.beam_elevations_deg = {6.0, 4.0, 2.0, 0.0, -2.0, -4.0, -6.0};
    sensor.azimuth_steps = 3600;
    sensor.range_noise_stddev = sigma;
    const Lidar lidar(sensor, exactOptions());
    const double distance = 10.0;
    const SimulatedScan scan = lidar.sweep(wallScene(distance), atOrigin, 0.0, 11);
    const std::vector<double> elevations = elevationsOf(sensor);
    double sum = 0.0, sum_squares = 0.0;
    for (size_t i = 0; i < scan.cloud.size(); ++i) {
      const double azimuth = azimuthOf(lidar, stepOf(lidar, scan.cloud.points[i]));
      const double exact = distance / (std::cos(elevations[scan.cloud.ring[i]]) * std::cos(azimuth));
      const double error = rangeOf(scan.cloud, i) - exact;
      sum += error;
      sum_squares += error * error;
    }
    const double count = static_cast<double>(scan.cloud.size());
    ASSERT_GT(count, 5000.0);
    const double mean = sum / count;
    const double stddev = std::sqrt(sum_squares / count - mean * mean);
    EXPECT_NEAR(stddev, sigma, 0.1 * sigma);
    EXPECT_NEAR(mean, 0.0, 0.05 * sigma);
  }
}

TEST(Lidar, DropoutsRemoveTheirShareOfReturns) {
  const SensorConfig sensor = exactSensor();
  LidarOptions options = exactOptions();
  const Scene scene(std::make_shared<FlatGround>(-kSensorHeight), {});
  const size_t all = Lidar(sensor, options).sweep(scene, atOrigin, 0.0, 1).cloud.size();
  options.dropout_probability = 0.2;
  const size_t kept = Lidar(sensor, options).sweep(scene, atOrigin, 0.0, 1).cloud.size();
  EXPECT_NEAR(static_cast<double>(kept) / all, 0.8, 0.02);
}

TEST(Lidar, IntensityFallsWithIncidence) {
  const SensorConfig sensor = exactSensor();
  const Lidar lidar(sensor, exactOptions());
  const SimulatedScan scan = lidar.sweep(wallScene(10.0), atOrigin, 0.0, 1);
  // Straight ahead the beam meets the wall head on; at 60 deg azimuth, at 60 deg incidence.
  float head_on = 0.0f, oblique = 1.0f;
  for (size_t i = 0; i < scan.cloud.size(); ++i) {
    if (scan.cloud.ring[i] != 2) continue;  // the horizontal beam
    const double azimuth = azimuthOf(lidar, stepOf(lidar, scan.cloud.points[i]));
    if (std::abs(azimuth) < 1e-9) head_on = scan.cloud.intensity[i];
    if (std::abs(azimuth - M_PI / 3.0) < 1e-9) oblique = scan.cloud.intensity[i];
  }
  EXPECT_NEAR(head_on, 0.6f, 1e-6);
  EXPECT_NEAR(oblique, 0.3f, 1e-6);
}

TEST(Lidar, MotionDuringTheSweepMovesLaterFirings) {
  SensorConfig sensor = exactSensor();
  const Scene scene = wallScene(20.0);
  const auto moving = [](double time) {
    Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
    pose.translation().x() = 10.0 * time;  // 10 m/s toward the wall
    return pose;
  };
  LidarOptions options = exactOptions();
  const SimulatedScan still = Lidar(sensor, options).sweep(scene, moving, 0.0, 1);
  options.deskewed = false;
  const Lidar skewed_lidar(sensor, options);
  const SimulatedScan skewed = skewed_lidar.sweep(scene, moving, 0.0, 1);
  ASSERT_GT(skewed.cloud.size(), 1000u);
  for (size_t i = 0; i < skewed.cloud.size(); ++i) {
    // Each firing sees the wall from where the sensor is at its time.
    EXPECT_NEAR(skewed.cloud.points[i].x(), 20.0 - 10.0 * skewed.cloud.time[i], 1e-4);
  }
  for (const Eigen::Vector3f& point : still.cloud.points) EXPECT_NEAR(point.x(), 20.0, 1e-5);
}

// KITTI's convention, as KISS-ICP's loader applies it: a point's time is the sweep fraction
// 0.5 (1 - atan2(y, x) / pi) of its azimuth, and the scan's stamp is mid-sweep.
TEST(Lidar, AzimuthConventionTimesFollowFromTheAzimuthAroundMidSweep) {
  const auto moving = [](double time) {
    Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
    pose.translation().x() = 10.0 * time;  // 10 m/s toward the wall
    return pose;
  };
  LidarOptions options = exactOptions();
  options.deskewed = false;
  options.time_convention = TimeConvention::azimuth;
  const Lidar lidar(exactSensor(), options);
  const double start = 0.5;  // 15 m before the wall
  const SimulatedScan scan = lidar.sweep(wallScene(20.0), moving, start, 1);
  EXPECT_EQ(lidar.referenceOffset(), 0.5 * lidar.sweepDuration());
  EXPECT_DOUBLE_EQ(scan.cloud.stamp, start + 0.05);
  EXPECT_TRUE(scan.cloud.time.empty()) << "a .bin-like scan has no per-point times";
  ASSERT_GT(scan.cloud.size(), 1000u);
  double earliest = 1.0, latest = 0.0;
  for (const Eigen::Vector3f& point : scan.cloud.points) {
    const double fraction = 0.5 * (1.0 - std::atan2(point.y(), point.x()) / M_PI);
    const double time = start + fraction * lidar.sweepDuration();
    // Fired from where the sensor was at that time.
    EXPECT_NEAR(point.x(), 20.0 - 10.0 * time, 1e-4);
    earliest = std::min(earliest, fraction);
    latest = std::max(latest, fraction);
  }
  // The wall ahead is seen in the sweep's middle half, symmetric about mid-sweep, when the sensor faces it.
  EXPECT_GT(earliest, 0.25);
  EXPECT_LT(latest, 0.75);
  EXPECT_NEAR(earliest + latest, 1.0, 0.01);
}

// The sweep starts where the sensor config says and turns its way: here counter-clockwise from straight
// ahead, so that a quarter sweep in, the head faces left.
TEST(Lidar, SweepFollowsTheConfiguredStartAndDirection) {
  SensorConfig sensor = exactSensor();
  sensor.clockwise = false;
  sensor.sweep_start_azimuth_deg = 0.0;
  LidarOptions options = exactOptions();
  options.deskewed = false;
  const Lidar lidar(sensor, options);
  const SimulatedScan scan = lidar.sweep(Scene(std::make_shared<FlatGround>(-kSensorHeight), {}), atOrigin, 0.0, 1);
  ASSERT_EQ(scan.cloud.time.size(), scan.cloud.size());
  ASSERT_GT(scan.cloud.size(), 1000u);
  for (size_t i = 0; i < scan.cloud.size(); ++i) {
    const double turned = 2.0 * M_PI * scan.cloud.time[i] / lidar.sweepDuration();
    const Eigen::Vector3f& p = scan.cloud.points[i];
    EXPECT_NEAR(std::remainder(std::atan2(p.y(), p.x()) - turned, 2.0 * M_PI), 0.0, 1e-5);
  }
}

TEST(Lidar, WeakEchoesThinOutWithRange) {
  SensorConfig sensor = exactSensor();
  sensor.beam_elevations_deg = {-1.0, -20.0};  // the road at 99 m and at 4.8 m
  LidarOptions options = exactOptions();
  options.detection_threshold = LidarOptions().detection_threshold;
  const Lidar lidar(sensor, options);
  const Scene scene(std::make_shared<FlatGround>(-kSensorHeight), {});
  const SimulatedScan scan = lidar.sweep(scene, atOrigin, 0.0, 3);
  std::vector<double> share(2, 0.0);
  for (const uint16_t ring : scan.cloud.ring) share[ring] += 1.0 / lidar.azimuthSteps();
  EXPECT_GT(share[1], 0.99);
  EXPECT_LT(share[0], 0.5);
  EXPECT_GT(share[0], 0.05);
}

TEST(Lidar, TheCarHidesTheRoadJustInFrontAndBehind) {
  SensorConfig sensor = exactSensor();
  sensor.beam_elevations_deg = {-24.9};
  sensor.azimuth_steps = 360;
  LidarOptions options = exactOptions();
  options.vehicle_body = LidarOptions::roofMountedCar();
  const Lidar lidar(sensor, options);
  const SimulatedScan scan = lidar.sweep(Scene(std::make_shared<FlatGround>(-kSensorHeight), {}), atOrigin, 0.0, 1);
  std::vector<bool> seen(lidar.azimuthSteps(), false);
  for (const Eigen::Vector3f& point : scan.cloud.points) seen[stepOf(lidar, point)] = true;
  const auto seenAt = [&](double degrees) {
    return seen[static_cast<int>(std::lround((180.0 - degrees) / 360.0 * lidar.azimuthSteps())) % lidar.azimuthSteps()];
  };
  EXPECT_FALSE(seenAt(0.0));    // bonnet
  EXPECT_FALSE(seenAt(180.0));  // boot
  EXPECT_TRUE(seenAt(90.0));    // past the rounded roof, to the sides
  EXPECT_TRUE(seenAt(-90.0));
}

TEST(Lidar, WindowsReturnNothing) {
  // A facade 10 m ahead with one storey of windows: 1 m of wall, 1 m of glass, then wall again.
  WindowGrid windows;
  windows.storey_height = 3.0;
  windows.sill_height = 1.0;
  windows.window_height = 1.0;
  windows.spacing = 4.0;
  windows.window_width = 2.0;
  Primitive facade{uprightBox(Eigen::Vector3d(10.5, 0.0, 0.0), Eigen::Vector3d(1.0, 8.0, 3.0), 0.0), 0.5f, windows};
  // The face spans y in [-4, 4]: two bays of 4 m with glass in their middle 2 m, so glass where
  // 1 < |y| < 3 and, 1 m above the box's bottom at z = -1.5, where -0.5 <= z < 0.5.
  const Scene scene(nullptr, {facade});
  const auto reflectivityToward = [&](double y, double z) {
    const Eigen::Vector3d target(10.0, y, z);
    const auto hit = scene.cast(Ray{Eigen::Vector3d::Zero(), target.normalized()}, 50.0);
    return hit ? hit->reflectivity : -1.0f;
  };
  EXPECT_EQ(reflectivityToward(0.0, 0.0), 0.5f);   // wall between windows
  EXPECT_EQ(reflectivityToward(2.0, 0.0), 0.0f);   // glass
  EXPECT_EQ(reflectivityToward(2.0, 1.0), 0.5f);   // wall above the window
  EXPECT_EQ(reflectivityToward(2.0, -1.0), 0.5f);  // wall below the sill
  SensorConfig sensor = exactSensor();
  sensor.beam_elevations_deg = {0.0};
  const Lidar lidar(sensor, exactOptions());
  const SimulatedScan scan = lidar.sweep(scene, atOrigin, 0.0, 1);
  for (const Eigen::Vector3f& point : scan.cloud.points) {
    EXPECT_TRUE(std::abs(point.y()) <= 1.0f + 1e-3f || std::abs(point.y()) >= 3.0f - 1e-3f) << point.y();
  }
  EXPECT_GT(scan.cloud.size(), 0u);
}

// A wall of leaves: with foliage_depth each beam reaches in by an exponential depth, at most three
// means; a plain wall beside it stays exact.
TEST(Lidar, BeamsReachIntoLeavesBeforeTheyEcho) {
  const double distance = 12.0;
  Scene plain = wallScene(distance);
  Primitive leaves{OrientedBox{Eigen::Vector3d(distance + 50.0, 0.0, 0.0), Eigen::Matrix3d::Identity(),
                               Eigen::Vector3d(50.0, 1000.0, 1000.0)},
                   0.6f};
  leaves.foliage = true;
  const Scene foliage(nullptr, {leaves});
  LidarOptions options = exactOptions();
  options.foliage_depth = 0.5;
  const Lidar lidar(exactSensor(), options);

  for (const Eigen::Vector3f& point : lidar.sweep(plain, atOrigin, 0.0, 1).cloud.points) {
    EXPECT_NEAR(point.x(), distance, 1e-5);
  }
  const SimulatedScan scan = lidar.sweep(foliage, atOrigin, 0.0, 1);
  ASSERT_GT(scan.cloud.size(), 1000u);
  double depth_sum = 0.0;
  for (size_t i = 0; i < scan.cloud.size(); ++i) {
    EXPECT_EQ(scan.surface[i], SurfaceKind::foliage);
    const double exact_range = distance / scan.cloud.points[i].cast<double>().normalized().x();
    const double depth = rangeOf(scan.cloud, i) - exact_range;
    EXPECT_GE(depth, -1e-4);
    EXPECT_LE(depth, 1.5 + 1e-4);
    depth_sum += depth;
  }
  // The mean of min(X, 3 m) for X exponential with mean m is m (1 - e^-3).
  EXPECT_NEAR(depth_sum / scan.cloud.size(), 0.5 * (1.0 - std::exp(-3.0)), 0.02);
}

// A box 6 m ahead in front of a wall 10 m ahead and 30 m wide: the firing beside each of the box's
// vertical edges returns from between the two surfaces when mixed pixels are certain, and none does
// without them. The wall seen obliquely (up to 56 degrees) is no depth edge.
TEST(Lidar, MixedPixelsLieBetweenTheSurfacesOfADepthEdge) {
  Scene scene(nullptr, {{OrientedBox{Eigen::Vector3d(60.0, 0.0, 0.0), Eigen::Matrix3d::Identity(),
                                     Eigen::Vector3d(50.0, 15.0, 1000.0)},
                         0.6f},
                        {uprightBox(Eigen::Vector3d(6.5, 0.0, 0.0), Eigen::Vector3d(1.0, 2.0, 1000.0), 0.0), 0.6f}});
  const auto between_count = [&](double probability) {
    LidarOptions options = exactOptions();
    options.mixed_pixel_probability = probability;
    SensorConfig sensor = exactSensor();
    sensor.beam_elevations_deg = {0.0};
    const SimulatedScan scan = Lidar(sensor, options).sweep(scene, atOrigin, 0.0, 1);
    int between = 0;
    for (const Eigen::Vector3f& point : scan.cloud.points) {
      EXPECT_TRUE(point.x() >= 6.0f - 1e-4f && point.x() <= 10.0f + 1e-4f) << point.transpose();
      between += point.x() > 6.0f + 1e-3f && point.x() < 10.0f - 1e-3f ? 1 : 0;
    }
    return between;
  };
  EXPECT_EQ(between_count(0.0), 0);
  // One firing at each of the two edges: the last on one surface before the range jumps.
  EXPECT_EQ(between_count(1.0), 2);
}

// An HDL-64E with exact ranges apart from its lasers' calibration errors.
SensorConfig exactHdl64() {
  Config config;
  loadSensor("hdl64", config);
  config.sensor.range_noise_stddev = 0.0;
  return config.sensor;
}

// Per ring that saw anything, the value of `of_point` for its points (by index), after checking that
// it is the same for all of them, as a laser's calibration error is.
std::vector<double> constantPerRing(const SimulatedScan& scan, int rings, const std::function<double(size_t)>& of_point) {
  std::vector<double> low(rings, INFINITY), high(rings, -INFINITY);
  for (size_t i = 0; i < scan.cloud.size(); ++i) {
    const double v = of_point(i);
    low[scan.cloud.ring[i]] = std::min(low[scan.cloud.ring[i]], v);
    high[scan.cloud.ring[i]] = std::max(high[scan.cloud.ring[i]], v);
  }
  std::vector<double> per_ring;
  for (int ring = 0; ring < rings; ++ring) {
    if (!std::isfinite(low[ring])) continue;  // the ring saw nothing
    EXPECT_NEAR(low[ring], high[ring], 2e-4) << "ring " << ring;
    per_ring.push_back(0.5 * (low[ring] + high[ring]));
  }
  return per_ring;
}

double spread(const std::vector<double>& values) {
  const double mean = std::accumulate(values.begin(), values.end(), 0.0) / values.size();
  double squares = 0.0;
  for (const double v : values) squares += (v - mean) * (v - mean);
  return std::sqrt(squares / (values.size() - 1));
}

// Each laser of a miscalibrated unit reads every range long or short by its own offset, the same on
// every sweep; the offsets spread as asked, and another unit has other offsets.
TEST(Lidar, EachLaserReadsItsOwnConstantRangeOffset) {
  constexpr double kBias = 0.02;
  LidarOptions options = exactOptions();
  options.beam_range_bias = kBias;
  const double distance = 12.0;
  const auto offsets = [&](uint64_t unit, uint64_t sweep) {
    const Lidar lidar(exactHdl64(), options, unit);
    const SimulatedScan scan = lidar.sweep(wallScene(distance), atOrigin, 0.0, sweep);
    EXPECT_GT(scan.cloud.size(), 10000u);
    return constantPerRing(scan, lidar.beamCount(), [&](size_t i) {
      const Eigen::Vector3d point = scan.cloud.points[i].cast<double>();
      return point.norm() - distance / point.normalized().x();  // along the nominal direction
    });
  };
  const std::vector<double> unit_one = offsets(1, 1);
  ASSERT_EQ(unit_one.size(), 64u);
  EXPECT_GT(spread(unit_one), 0.6 * kBias);
  EXPECT_LT(spread(unit_one), 1.4 * kBias);
  EXPECT_EQ(offsets(1, 2), unit_one);
  EXPECT_NE(offsets(2, 1), unit_one);
}

// A unit whose distance calibration is off as a whole reads every range of every laser long by the same
// offset; each laser's own offset, when it has one, comes on top of it.
TEST(Lidar, EveryLaserReadsTheUnitsRangeOffset) {
  constexpr double kOffset = 0.05;
  LidarOptions options = exactOptions();
  options.range_offset = kOffset;
  const double distance = 12.0;
  const auto sweepOfWall = [&] {
    const Lidar lidar(exactHdl64(), options, 1);
    return lidar.sweep(wallScene(distance), atOrigin, 0.0, 1);
  };
  const auto offsetOf = [&](const SimulatedScan& scan, size_t i) {
    const Eigen::Vector3d point = scan.cloud.points[i].cast<double>();
    return point.norm() - distance / point.normalized().x();  // along the nominal direction
  };
  const SimulatedScan whole = sweepOfWall();
  ASSERT_GT(whole.cloud.size(), 10000u);
  for (size_t i = 0; i < whole.cloud.size(); ++i) EXPECT_NEAR(offsetOf(whole, i), kOffset, 1e-4);

  options.beam_range_bias = 0.02;
  const SimulatedScan both = sweepOfWall();
  const std::vector<double> per_ring =
      constantPerRing(both, 64, [&](size_t i) { return offsetOf(both, i); });
  ASSERT_EQ(per_ring.size(), 64u);
  const double mean = std::accumulate(per_ring.begin(), per_ring.end(), 0.0) / per_ring.size();
  EXPECT_NEAR(mean, kOffset, 0.01);  // 64 lasers' own offsets of 2 cm average to within 2.5 mm
  EXPECT_GT(spread(per_ring), 0.01);
}

// One sweep of the exact HDL-64E over a flat road, by a unit with the calibration errors of `options`.
SimulatedScan flatRoadSweep(const LidarOptions& options) {
  const Lidar lidar(exactHdl64(), options, 1);
  return lidar.sweep(Scene(std::make_shared<FlatGround>(-kSensorHeight), {}), atOrigin, 0.0, 1);
}

// Each laser of a miscalibrated unit fires off its nominal elevation by its own angle while its points
// are computed along the nominal one: on a flat road every ring lies at its own height.
TEST(Lidar, EachLaserFiresOffItsNominalElevation) {
  constexpr double kErrorDegrees = 0.1;
  LidarOptions options = exactOptions();
  options.beam_elevation_error = kErrorDegrees;
  const SimulatedScan scan = flatRoadSweep(options);
  const std::vector<double> nominal = elevationsOf(exactHdl64());
  // The elevation each ring really fired at, from its exact range to the road, less its nominal one.
  const std::vector<double> per_ring = constantPerRing(scan, static_cast<int>(nominal.size()), [&](size_t i) {
    return std::asin(-kSensorHeight / scan.cloud.points[i].cast<double>().norm()) - nominal[scan.cloud.ring[i]];
  });
  ASSERT_GT(per_ring.size(), 50u);
  EXPECT_GT(spread(per_ring), 0.6 * kErrorDegrees * M_PI / 180.0);
  EXPECT_LT(spread(per_ring), 1.4 * kErrorDegrees * M_PI / 180.0);
  for (size_t i = 0; i < scan.cloud.size(); ++i) {
    const Eigen::Vector3d point = scan.cloud.points[i].cast<double>();
    EXPECT_NEAR(std::asin(point.z() / point.norm()), nominal[scan.cloud.ring[i]], 1e-5);
  }
}

// The lower block of a unit with lower_block_rise fires from below the sensor's origin while its points
// are computed from the origin, along the nominal elevations: on a flat road its rings lie that much
// higher, the upper block's where the road is.
TEST(Lidar, TheLowerBlockReadsTheRoadHigh) {
  constexpr double kRise = 0.03;
  LidarOptions options = exactOptions();
  options.lower_block_rise = kRise;
  const SimulatedScan scan = flatRoadSweep(options);
  const std::vector<double> nominal = elevationsOf(exactHdl64());
  const double middle = 0.5 * (*std::max_element(nominal.begin(), nominal.end()) +
                               *std::min_element(nominal.begin(), nominal.end()));
  size_t lower = 0;
  size_t upper = 0;
  for (size_t i = 0; i < scan.cloud.size(); ++i) {
    const Eigen::Vector3d point = scan.cloud.points[i].cast<double>();
    const double beam = nominal[scan.cloud.ring[i]];
    const bool in_lower_block = beam < middle;
    lower += in_lower_block;
    upper += !in_lower_block;
    EXPECT_NEAR(point.z(), -kSensorHeight + (in_lower_block ? kRise : 0.0), 1e-4) << "ring " << scan.cloud.ring[i];
    EXPECT_NEAR(std::asin(point.z() / point.norm()), beam, 1e-5);
  }
  EXPECT_GT(lower, 10000u);
  EXPECT_GT(upper, 10000u);
}

TEST(Lidar, RejectsUnusableSensors) {
  SensorConfig sensor = exactSensor();
  sensor.azimuth_steps = 0;
  EXPECT_THROW(Lidar(sensor, exactOptions()), std::invalid_argument);
  LidarOptions options = exactOptions();
  options.dropout_probability = 1.5;
  EXPECT_THROW(Lidar(exactSensor(), options), std::invalid_argument);
  options = exactOptions();
  options.foliage_depth = -0.1;
  EXPECT_THROW(Lidar(exactSensor(), options), std::invalid_argument);
  options = exactOptions();
  options.mixed_pixel_probability = 2.0;
  EXPECT_THROW(Lidar(exactSensor(), options), std::invalid_argument);
  options = exactOptions();
  options.beam_range_bias = -0.01;
  EXPECT_THROW(Lidar(exactSensor(), options), std::invalid_argument);
  options = exactOptions();
  options.beam_elevation_error = -0.1;
  EXPECT_THROW(Lidar(exactSensor(), options), std::invalid_argument);
  options = exactOptions();
  options.range_offset = -1.5;
  EXPECT_THROW(Lidar(exactSensor(), options), std::invalid_argument);
  options.range_offset = NAN;
  EXPECT_THROW(Lidar(exactSensor(), options), std::invalid_argument);
}

}  // namespace
}  // namespace elo::sim
