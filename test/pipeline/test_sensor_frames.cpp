// Each sensor configuration (config/*.yaml) against a real frame of its LiDAR: one decoded frame per model
// in ../shared/data/real/sensors/ (tier4/nebula's decoder reference data, x y z only). The frames were
// decoded with the calibration tables the configurations copy, so every point lies on a beam of the
// table; the checks are that the sensor-fit check finds nothing to say (0 % misfit), that every point
// lies within kOnBeamDeg of a configured beam, and that the point's row from its elevation is its beam's
// row (the row a driver's ring gives). That each beam has a row of its own, every configuration's
// (test_config_yaml) checks.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <map>
#include <ostream>
#include <set>
#include <string>
#include <vector>

#include "elo/io/config_yaml.hpp"
#include "elo/io/pcd.hpp"
#include "elo/sensor/sensor_fit.hpp"
#include "elo/sensor/sensor_model.hpp"

namespace elo {
namespace {

const std::string kFrames = std::string(ELO_SHARED_DATA) + "/real/sensors/";
constexpr double kOnBeamDeg = 0.01;  // the tables' rounding (0.001 deg) and float coordinates

struct RealFrame {
  std::string config;  // config/NAME.yaml
  std::string file;    // in kFrames
};

// gtest names a test by this rather than by its bytes.
void PrintTo(const RealFrame& frame, std::ostream* out) { *out << frame.file << " under config/" << frame.config << ".yaml"; }

std::string frameName(const testing::TestParamInfo<RealFrame>& info) {
  std::string name = info.param.config;
  for (char& c : name) c = std::isalnum(static_cast<unsigned char>(c)) ? c : '_';
  return name;
}

SensorConfig sensorOf(const std::string& name) {
  Config config;
  loadConfigYaml(std::string(ELO_SOURCE_DIR) + "/config/" + name + ".yaml", config);
  return config.sensor;
}

double elevationDeg(const Vec3f& p) {
  return std::atan2(static_cast<double>(p.z()), std::hypot(static_cast<double>(p.x()), p.y())) * 180.0 / M_PI;
}

// Index of the table's beam nearest `elevation` (deg).
size_t nearestBeam(const std::vector<float>& beams, double elevation_deg) {
  size_t nearest = 0;
  for (size_t beam = 1; beam < beams.size(); ++beam) {
    if (std::fabs(beams[beam] * 180.0 / M_PI - elevation_deg) <
        std::fabs(beams[nearest] * 180.0 / M_PI - elevation_deg)) {
      nearest = beam;
    }
  }
  return nearest;
}

class SensorFrame : public testing::TestWithParam<RealFrame> {};

TEST_P(SensorFrame, FitsItsConfigurationBeamByBeam) {
  const std::string path = kFrames + GetParam().file;
  if (!std::filesystem::exists(path)) GTEST_SKIP() << "real frame not found at " << path << " (shared data absent)";
  const SensorConfig sensor = sensorOf(GetParam().config);
  const PointCloud cloud = readPcd(path);

  const SensorFit fit = checkSensorFit(cloud, sensor, 1);
  EXPECT_GE(fit.sampled, 5000u);
  EXPECT_EQ(fit.misplaced(), 0u) << fit.above << " above, " << fit.below << " below the field of view";
  EXPECT_EQ(fit.warning(sensor), "");

  const std::vector<float> beams = beamElevations(sensor);
  const SphericalProjection projection = SphericalProjection::fromConfig(sensor);
  size_t off_beam = 0;
  size_t off_row = 0;
  std::set<size_t> seen;
  for (const Vec3f& point : cloud.points) {
    const double range = point.norm();
    if (!(range >= sensor.min_range && range <= sensor.max_range)) continue;
    const double elevation = elevationDeg(point);
    const size_t beam = nearestBeam(beams, elevation);
    seen.insert(beam);
    off_beam += std::fabs(beams[beam] * 180.0 / M_PI - elevation) > kOnBeamDeg ? 1 : 0;
    off_row += projection.rowOfElevation(static_cast<float>(elevation * M_PI / 180.0)) !=
                       projection.rowOfElevation(beams[beam])
                   ? 1
                   : 0;
  }
  EXPECT_EQ(off_beam, 0u) << "points over " << kOnBeamDeg << " deg from every configured beam";
  EXPECT_EQ(off_row, 0u) << "points whose elevation puts them in another row than their beam's";
  EXPECT_GE(seen.size(), beams.size() / 2) << "beams seen in the frame";
}

INSTANTIATE_TEST_SUITE_P(RealFrames, SensorFrame,
                         testing::Values(RealFrame{"vlp16", "velodyne_vlp16.pcd"}, RealFrame{"vlp32", "velodyne_vlp32.pcd"},
                                         RealFrame{"vls128", "velodyne_vls128.pcd"},
                                         RealFrame{"pandar40p", "hesai_40p.pcd"}, RealFrame{"pandar64", "hesai_64.pcd"},
                                         RealFrame{"xt16", "hesai_xt16.pcd"}, RealFrame{"xt32", "hesai_xt32.pcd"},
                                         RealFrame{"xt32m", "hesai_xt32m.pcd"}, RealFrame{"ot128", "hesai_ot128.pcd"},
                                         RealFrame{"qt64", "hesai_qt64.pcd"}, RealFrame{"qt128", "hesai_qt128.pcd"}),
                         frameName);

// The check tells the sensors apart: the frames under another sensor's configuration.
TEST(SensorFrame, AnotherSensorsConfigurationDoesNotFit) {
  const std::map<std::string, std::string> wrong = {
      {"velodyne_vls128.pcd", "hdl64"}, {"hesai_64.pcd", "hdl64"}, {"hesai_qt128.pcd", "os1-128"}};
  for (const auto& [file, config] : wrong) {
    const std::string path = kFrames + file;
    if (!std::filesystem::exists(path)) GTEST_SKIP() << "real frame not found at " << path << " (shared data absent)";
    const SensorConfig sensor = sensorOf(config);
    EXPECT_NE(checkSensorFit(readPcd(path), sensor, 1).warning(sensor), "") << file << " under " << config;
  }
}

}  // namespace
}  // namespace elo
