// The check that a cloud fits the configured sensor (elo/sensor/sensor_fit.hpp), on points placed at known
// elevations and rings.
#include <gtest/gtest.h>

#include <cmath>

#include "elo/sensor/sensor_fit.hpp"
#include "elo/sensor/sensor_model.hpp"

namespace elo {
namespace {

// A point 20 m away at `elevation_deg`, straight ahead.
Vec3f pointAtElevation(double elevation_deg) {
  const double elevation = elevation_deg * M_PI / 180.0;
  return Vec3f(static_cast<float>(20.0 * std::cos(elevation)), 0.0f, static_cast<float>(20.0 * std::sin(elevation)));
}

// The nominal elevation (deg) of the beam `sensor` numbers `ring`.
double ringElevationDeg(const SensorConfig& sensor, int ring) { return ringElevations(sensor)[ring] * 180.0 / M_PI; }

PointCloud cloudOf(const std::vector<std::pair<double, uint16_t>>& elevations_and_rings) {
  PointCloud cloud;
  for (const auto& [elevation, ring] : elevations_and_rings) {
    cloud.points.push_back(pointAtElevation(elevation));
    cloud.ring.push_back(ring);
  }
  return cloud;
}

// The HDL-64E defaults: image from +3 to -25 deg, 64 beams.
TEST(SensorFit, CountsPointsAboveAndBelowTheImageAndRingsPastTheBeams) {
  const SensorConfig hdl64;
  PointCloud cloud = cloudOf({{10.0, 0}, {-30.0, 63}, {-10.0, 70}, {ringElevationDeg(hdl64, 40), 40}, {2.0, 63}});  // ring 63: the top beam, +2 deg
  cloud.points.push_back(Vec3f(NAN, 0.0f, 0.0f));  // not finite: not sampled
  cloud.ring.push_back(2);
  cloud.points.push_back(Vec3f(1.0f, 0.0f, 0.0f));  // closer than sensor.min_range: not sampled
  cloud.ring.push_back(2);
  const SensorFit fit = checkSensorFit(cloud, hdl64, 1);
  EXPECT_EQ(fit.sampled, 5u);
  EXPECT_EQ(fit.above, 1u);
  EXPECT_EQ(fit.below, 1u);
  EXPECT_EQ(fit.unknown_ring, 1u);
  EXPECT_EQ(fit.off_beam, 0u);
  const std::string warning = fit.warning(hdl64);
  EXPECT_NE(warning.find("60% of the scan's points do not fit the sensor model 'hdl64'"), std::string::npos) << warning;
  EXPECT_NE(warning.find("past its 64 beams"), std::string::npos) << warning;
}

// Rings numbered the other way (ouster_ros's from the top, where the HDL-64E settings expect
// velodyne_pointcloud's from the bottom): each point's ring names a beam on the other side of the field
// of view.
TEST(SensorFit, CountsPointsFarFromTheirRingsBeam) {
  const SensorConfig hdl64;
  ASSERT_EQ(hdl64.ring_zero, RingZero::bottom);
  std::vector<std::pair<double, uint16_t>> points;
  for (uint16_t ring = 0; ring < 64; ++ring) points.push_back({hdl64.beam_elevations_deg[ring], ring});
  const SensorFit flipped = checkSensorFit(cloudOf(points), hdl64, 1);
  EXPECT_EQ(flipped.sampled, 64u);
  EXPECT_GE(flipped.off_beam, 56u);  // all but the few beams near the table's middle
  EXPECT_NE(flipped.warning(hdl64).find("over 1.5 deg from their ring's beam"), std::string::npos);
  SensorConfig top_first = hdl64;
  top_first.ring_zero = RingZero::top;
  EXPECT_EQ(checkSensorFit(cloudOf(points), top_first, 1).off_beam, 0u);
  points.clear();
  for (uint16_t ring = 0; ring < 64; ++ring) points.push_back({ringElevationDeg(hdl64, ring) - 0.5, ring});
  EXPECT_EQ(checkSensorFit(cloudOf(points), hdl64, 1).off_beam, 0u);  // half a degree off: calibration
}

// A driver that numbers its rings in neither elevation order (Hesai's QT128: its correction file's
// channels) is described by the table in that order: ring k is entry k, and the simulator fires it so.
TEST(SensorFit, RingZeroTableTakesTheTablesOrder) {
  SensorConfig sensor;
  sensor.ring_zero = RingZero::table;
  sensor.beam_count = 4;
  sensor.beam_elevations_deg = {-20.0, -10.0, 0.0, -15.0};
  EXPECT_EQ(ringOfBeam(sensor, 3), 3);
  std::vector<std::pair<double, uint16_t>> points;
  for (uint16_t ring = 0; ring < 4; ++ring) points.push_back({sensor.beam_elevations_deg[ring], ring});
  EXPECT_EQ(checkSensorFit(cloudOf(points), sensor, 1).misplaced(), 0u);
  sensor.ring_zero = RingZero::bottom;
  EXPECT_EQ(checkSensorFit(cloudOf(points), sensor, 1).off_beam, 4u);
}

// Close in, where the lasers' offsets on the head bend elevations, a ring is not checked against its beam.
TEST(SensorFit, LeavesRingsOfClosePointsUnchecked) {
  PointCloud cloud = cloudOf({{-10.0, 0}});
  cloud.points[0] *= 0.5f;  // 10 m away
  EXPECT_EQ(checkSensorFit(cloud, SensorConfig(), 1).off_beam, 0u);
}

TEST(SensorFit, RingsAreLeftUncheckedWhenTheCloudHasNone) {
  PointCloud cloud = cloudOf({{-10.0, 70}});
  cloud.ring.clear();
  EXPECT_EQ(checkSensorFit(cloud, SensorConfig(), 1).unknown_ring, 0u);
}

// A few stray points (multipath, a reflection above the horizon) are no reason to warn; a sixth is.
TEST(SensorFit, WarnsOnlyAboveTheMisplacedShare) {
  std::vector<std::pair<double, uint16_t>> points(100, {ringElevationDeg(SensorConfig(), 10), 10});
  for (int i = 0; i < 5; ++i) points[i] = {10.0, 10};
  const SensorConfig hdl64;
  EXPECT_EQ(checkSensorFit(cloudOf(points), hdl64, 1).warning(hdl64), "");
  points[5] = {10.0, 10};
  EXPECT_NE(checkSensorFit(cloudOf(points), hdl64, 1).warning(hdl64), "");
}

// The elevation correction is applied before the test, as the projection applies it.
TEST(SensorFit, TestsElevationsAfterTheCorrection) {
  SensorConfig sensor;
  sensor.elevation_correction_deg = 1.0;
  EXPECT_EQ(checkSensorFit(cloudOf({{2.5, 63}}), sensor, 1).above, 1u);
  EXPECT_EQ(checkSensorFit(cloudOf({{1.5, 63}}), sensor, 1).above, 0u);
}

TEST(SensorFit, SamplesEveryStrideThPoint) {
  const PointCloud cloud = cloudOf({{10.0, 0}, {-10.0, 0}, {10.0, 0}, {-10.0, 0}});
  const SensorFit fit = checkSensorFit(cloud, SensorConfig(), 2);
  EXPECT_EQ(fit.sampled, 2u);
  EXPECT_EQ(fit.above, 2u);
}

// Sixteen beams 2 deg apart (a VLP-16), one of them doubled (two lasers at one elevation are one row).
Config sixteenBeams(double outlier_distance) {
  Config config;
  config.sensor.beam_elevations_deg.clear();
  for (int beam = 0; beam < 16; ++beam) config.sensor.beam_elevations_deg.push_back(15.0 - 2.0 * beam);
  config.sensor.beam_elevations_deg.push_back(-1.0);
  config.normals.outlier_distance = outlier_distance;
  return config;
}

// The beams above and below lie range x tan(2 deg) away: 0.5 m at 14.3 m, 1.0 m at 28.6 m.
TEST(NormalReach, IsWhereTheAdjacentBeamsLieSigmaRApart) {
  EXPECT_NEAR(normalReach(sixteenBeams(0.5)), 0.5 / std::tan(2.0 * M_PI / 180.0), 1e-4);
  EXPECT_NEAR(normalReach(sixteenBeams(0.5)), 14.318, 1e-3);
  EXPECT_NEAR(normalReach(sixteenBeams(1.0)), 28.636, 1e-3);
  // The HDL-64E's beams, 0.33 deg apart in the upper block and 0.5 in the lower: the median 0.5 deg.
  EXPECT_NEAR(normalReach(Config()), 0.5 / std::tan(0.5 * M_PI / 180.0), 0.5);
}

TEST(NormalReach, WarnsBelowTheMinimumReachNamingTheSettingThatReachesIt) {
  const std::string warning = normalReachWarning(sixteenBeams(0.5));
  EXPECT_NE(warning.find("beyond 14 m"), std::string::npos) << warning;
  EXPECT_NE(warning.find("2.00 deg apart"), std::string::npos) << warning;
  EXPECT_NE(warning.find("set it to 0.9 m to reach 25 m"), std::string::npos) << warning;  // 25 tan(2 deg) = 0.87
  EXPECT_EQ(normalReachWarning(sixteenBeams(0.9)), "");
  EXPECT_EQ(normalReachWarning(Config()), "");
}

// A sensor that sees no farther than the reach, and estimators without test 1, lose nothing.
TEST(NormalReach, DoesNotWarnWhereNoPointLiesBeyondItOrTheMethodHasNoDistanceTest) {
  Config short_range = sixteenBeams(0.5);
  short_range.sensor.max_range = 14.0;
  EXPECT_EQ(normalReachWarning(short_range), "");
  for (const NormalMethod method : {NormalMethod::eigen, NormalMethod::cross_product}) {
    Config config = sixteenBeams(0.5);
    config.normals.method = method;
    EXPECT_TRUE(std::isinf(normalReach(config)));
    EXPECT_EQ(normalReachWarning(config), "");
  }
}

}  // namespace
}  // namespace elo
