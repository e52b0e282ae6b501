#include "elo/sensor/sensor_fit.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <utility>
#include <vector>

#include "core/common/eigen_interop.hpp"
#include "core/median.hpp"
#include "elo/sensor/sensor_model.hpp"

namespace elo {

namespace {

double percent(size_t part, size_t whole) { return whole > 0 ? 100.0 * part / whole : 0.0; }

// The median gap between adjacent beams (rad); 0 with fewer than two beams.
double medianBeamGap(const SensorConfig& sensor) {
  std::vector<float> elevations = beamElevations(sensor);
  std::sort(elevations.begin(), elevations.end());
  std::vector<double> gaps;
  for (size_t beam = 1; beam < elevations.size(); ++beam) {
    const double gap = static_cast<double>(elevations[beam]) - elevations[beam - 1];
    if (gap > 0.0) gaps.push_back(gap);  // two lasers at one elevation are one row
  }
  if (gaps.empty()) return 0.0;
  return upperMedian(std::move(gaps));
}

}  // namespace

SensorFit checkSensorFit(const PointCloud& cloud, const SensorConfig& sensor, size_t stride) {
  const ElevationCorrection correction = ElevationCorrection::fromConfig(sensor);
  const double min_squared = sensor.min_range * sensor.min_range;
  const double max_squared = sensor.max_range * sensor.max_range;
  const float fov_up = static_cast<float>(sensor.fov_up_deg * M_PI / 180.0);
  const float fov_down = static_cast<float>(sensor.fov_down_deg * M_PI / 180.0);
  const std::vector<float> beams = ringElevations(sensor);
  const double ring_check_squared = kRingCheckRange * kRingCheckRange;
  const float max_beam_offset = static_cast<float>(kMaxBeamOffsetDeg * M_PI / 180.0);
  const bool has_rings = cloud.ring.size() == cloud.points.size();
  SensorFit fit;
  for (size_t i = 0; i < cloud.points.size(); i += stride > 0 ? stride : 1) {
    const Float3 p = correction.apply(toFloat3(cloud.points[i]));
    const double horizontal_squared = static_cast<double>(p.x) * p.x + static_cast<double>(p.y) * p.y;
    const double range_squared = horizontal_squared + static_cast<double>(p.z) * p.z;
    if (!(range_squared >= min_squared && range_squared <= max_squared)) continue;  // and NaN
    ++fit.sampled;
    // The projection's own atan2: within 1e-5 rad, and a fraction of libm's cost on the GPU backend's budget.
    const float elevation = fastAtan2(p.z, static_cast<float>(std::sqrt(horizontal_squared)));
    if (elevation > fov_up) {
      ++fit.above;
    } else if (elevation < fov_down) {
      ++fit.below;
    } else if (has_rings && cloud.ring[i] >= beams.size()) {
      ++fit.unknown_ring;
    } else if (has_rings && range_squared >= ring_check_squared &&
               std::fabs(elevation - beams[cloud.ring[i]]) > max_beam_offset) {
      ++fit.off_beam;
    }
  }
  return fit;
}

std::string SensorFit::warning(const SensorConfig& sensor) const {
  if (sampled == 0 || misplaced() <= kMaxMisplacedShare * sampled) return "";
  char text[600];
  std::snprintf(text, sizeof text,
                "%.0f%% of the scan's points do not fit the sensor model '%s' (%.0f%% above its field of view's "
                "top at %+.1f deg, %.0f%% below its bottom at %+.1f deg, %.0f%% with a ring past its %zu beams: "
                "left out; %.0f%% over %.1f deg from their ring's beam: put in the wrong row): are the sensor.* "
                "settings this LiDAR's (config/*.yaml, --config), with the "
                "right sensor.ring_zero (velodyne_pointcloud counts rings up from the lowest beam, ouster_ros down "
                "from the highest)?",
                percent(misplaced(), sampled), sensor.name.c_str(), percent(above, sampled), sensor.fov_up_deg,
                percent(below, sampled), sensor.fov_down_deg, percent(unknown_ring, sampled),
                beamElevations(sensor).size(), percent(off_beam, sampled), kMaxBeamOffsetDeg);
  return text;
}

double normalReach(const Config& config) {
  const double gap = medianBeamGap(config.sensor);
  if (config.normals.method != NormalMethod::range_adaptive || gap <= 0.0) {
    return std::numeric_limits<double>::infinity();
  }
  return config.normals.outlier_distance / std::tan(gap);
}

std::string normalReachWarning(const Config& config) {
  const double reach = normalReach(config);
  if (reach >= std::min(kMinNormalReach, config.sensor.max_range)) return "";
  const double gap = medianBeamGap(config.sensor);
  // Rounded up to 0.1 m, as a setting is written.
  const double needed = std::ceil(10.0 * kMinNormalReach * std::tan(gap)) / 10.0;
  char text[400];
  std::snprintf(text, sizeof text,
                "points beyond %.0f m get no normal: the sensor's beams lie %.2f deg apart and "
                "normals.outlier_distance is %.2f m; set it to %.1f m to reach %.0f m (docs/parameters.md)",
                reach, gap * 180.0 / M_PI, config.normals.outlier_distance, needed, kMinNormalReach);
  return text;
}

}  // namespace elo
