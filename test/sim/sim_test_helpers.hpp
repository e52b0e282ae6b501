// Shared set-ups of the simulator tests: a small sensor for analytic scenes and range bookkeeping.
#pragma once

#include <cmath>
#include <vector>

#include "elo/config.hpp"
#include "elo/sensor/sensor_model.hpp"
#include "elo/sim/lidar.hpp"

namespace elo::sim::test {

// A noise-free, dropout-free sensor with a few beams above and below the horizon, so that analytic
// scenes can be checked ray by ray.
inline SensorConfig exactSensor() {
  SensorConfig sensor;
  sensor.name = "exact";
  sensor.beam_elevations_deg = {10.0, 2.0, 0.0, -1.0, -5.0, -12.5, -20.0, -24.9};
  sensor.beam_count = 8;
  sensor.ring_zero = RingZero::top;  // ring r is the table's beam r (the tests' beam tables count from the top)
  sensor.azimuth_steps = 720;
  sensor.min_range = 0.5;
  sensor.max_range = 120.0;
  sensor.range_noise_stddev = 0.0;
  return sensor;
}

inline LidarOptions exactOptions() {
  LidarOptions options;
  options.dropout_probability = 0.0;
  options.detection_threshold = 0.0;
  options.vehicle_body.clear();
  return options;
}

// The firing step of a point of a sweep with times in the field convention, recovered from its time.
inline int stepOf(const Lidar& lidar, float time) {
  return static_cast<int>(std::lround(time / lidar.sweepDuration() * lidar.azimuthSteps()));
}

// The firing step of a point, recovered from its azimuth: step 0 fires straight behind and the head
// turns clockwise seen from above.
inline int stepOf(const Lidar& lidar, const Eigen::Vector3f& point) {
  const double turned = (M_PI - std::atan2(point.y(), point.x())) / (2.0 * M_PI);  // in [0, 1]
  return static_cast<int>(std::lround(turned * lidar.azimuthSteps())) % lidar.azimuthSteps();
}

// Elevation (rad) of each beam as the simulator fires it.
// The beams' elevations indexed by the ring the simulator gives each (sensor.ring_zero).
inline std::vector<double> elevationsOf(const SensorConfig& sensor) {
  std::vector<double> elevations;
  for (const float elevation : ringElevations(sensor)) elevations.push_back(elevation);
  return elevations;
}

inline double azimuthOf(const Lidar& lidar, int step) { return M_PI - 2.0 * M_PI * step / lidar.azimuthSteps(); }

}  // namespace elo::sim::test
