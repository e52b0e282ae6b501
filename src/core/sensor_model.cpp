#include "elo/sensor/sensor_model.hpp"

#include <algorithm>

namespace elo {

namespace {
constexpr double kDegToRad = M_PI / 180.0;
}

SphericalProjection SphericalProjection::fromConfig(const SensorConfig& sensor) {
  SphericalProjection projection;
  projection.rows = sensor.image_height;
  projection.cols = sensor.image_width;
  projection.fov_up = static_cast<float>(sensor.fov_up_deg * kDegToRad);
  projection.fov_span = static_cast<float>((sensor.fov_up_deg - sensor.fov_down_deg) * kDegToRad);
  projection.min_range = static_cast<float>(sensor.min_range);
  projection.max_range = static_cast<float>(sensor.max_range);
  return projection;
}

BevProjection BevProjection::fromConfig(const BevConfig& bev) {
  BevProjection projection;
  projection.cell_size = static_cast<float>(bev.cell_size);
  projection.half_length = static_cast<float>(bev.half_length);
  projection.half_width = static_cast<float>(bev.half_width);
  projection.cols = static_cast<int>(std::lround(2.0 * bev.half_length / bev.cell_size));
  projection.rows = static_cast<int>(std::lround(2.0 * bev.half_width / bev.cell_size));
  return projection;
}

ElevationCorrection ElevationCorrection::fromConfig(const SensorConfig& sensor) {
  ElevationCorrection correction;
  correction.active = sensor.elevation_correction_deg != 0.0;
  correction.cos_angle = static_cast<float>(std::cos(sensor.elevation_correction_deg * kDegToRad));
  correction.sin_angle = static_cast<float>(std::sin(sensor.elevation_correction_deg * kDegToRad));
  return correction;
}

std::vector<float> beamElevations(const SensorConfig& sensor) {
  std::vector<float> elevations;
  if (!sensor.beam_elevations_deg.empty()) {
    for (double degrees : sensor.beam_elevations_deg) elevations.push_back(static_cast<float>(degrees * kDegToRad));
    return elevations;
  }
  // Evenly spread beams sit at the centres of equal slices of the field of view.
  const double span = sensor.fov_up_deg - sensor.fov_down_deg;
  for (int beam = 0; beam < sensor.beam_count; ++beam) {
    const double degrees = sensor.fov_up_deg - span * (beam + 0.5) / sensor.beam_count;
    elevations.push_back(static_cast<float>(degrees * kDegToRad));
  }
  return elevations;
}

int ringOfBeam(const SensorConfig& sensor, int beam) {
  // Counted without building the table: the simulator asks for every point.
  const int beams =
      sensor.beam_elevations_deg.empty() ? sensor.beam_count : static_cast<int>(sensor.beam_elevations_deg.size());
  return sensor.ring_zero == RingZero::bottom ? beams - 1 - beam : beam;
}

std::vector<float> ringElevations(const SensorConfig& sensor) {
  std::vector<float> elevations = beamElevations(sensor);
  if (sensor.ring_zero == RingZero::bottom) std::reverse(elevations.begin(), elevations.end());
  return elevations;
}

}  // namespace elo
