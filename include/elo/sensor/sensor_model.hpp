// The sensor model on the host: the projections of projections.hpp (which both backends call), the
// elevation correction for Eigen points, and the nominal beam elevations.
#pragma once

#include <vector>

#include "elo/config.hpp"
#include "elo/sensor/projections.hpp"
#include "elo/types.hpp"

namespace elo {

// Raises the elevation of a point by `angle` (rad) at constant range and azimuth: KITTI's correction.
inline Vec3f correctElevation(const Vec3f& p, float cos_angle, float sin_angle) {
  const Float3 corrected = correctElevation(Float3{p.x(), p.y(), p.z()}, cos_angle, sin_angle);
  return Vec3f(corrected.x, corrected.y, corrected.z);
}

// Nominal elevation (rad) of each beam, from the config's table (top to bottom, or in ring order with
// sensor.ring_zero table) or an even spread, top to bottom.
std::vector<float> beamElevations(const SensorConfig& sensor);
// The same, indexed by the ring a driver gives each beam (sensor.ring_zero).
std::vector<float> ringElevations(const SensorConfig& sensor);
// The ring a driver gives beam `beam` of beamElevations() (sensor.ring_zero).
int ringOfBeam(const SensorConfig& sensor, int beam);

}  // namespace elo
