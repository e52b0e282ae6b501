#include "elo/sim/lidar.hpp"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "elo/sensor/sensor_model.hpp"
#include "elo/sim/rng.hpp"

namespace elo::sim {
namespace {
constexpr double kEchoReferenceRange = 10.0;  // m at which the echo strength equals the intensity
constexpr double kMaxRangeOffset = 1.0;       // m: a unit off by more reads nonsense, not a calibration error

// The unit vector at `elevation` (cos, sin) and the azimuth of (azimuth_cos, azimuth_sin).
Eigen::Vector3d atAzimuth(const Eigen::Vector2d& elevation, double azimuth_cos, double azimuth_sin) {
  return Eigen::Vector3d(elevation.x() * azimuth_cos, elevation.x() * azimuth_sin, elevation.y());
}
}  // namespace

std::vector<Shape> LidarOptions::roofMountedCar() {
  // 4.8 m x 1.8 m with bonnet and boot 1.0 m above the road; the roof 1.33 m above the road, rounded
  // at its edges, so that the lowest beams clear it sideways as they do on KITTI's car.
  constexpr double kRoad = -1.73;
  const Ellipsoid cabin{Eigen::Vector3d(-0.2, 0.0, kRoad + 0.88), Eigen::Vector3d(1.3, 0.75, 0.45), 0.0};
  const OrientedBox body{Eigen::Vector3d(0.0, 0.0, kRoad + 0.65), Eigen::Matrix3d::Identity(),
                         Eigen::Vector3d(2.4, 0.9, 0.35)};
  return {cabin, body};
}

Lidar::Lidar(const SensorConfig& sensor, const LidarOptions& options, uint64_t unit_seed)
    : sensor_(sensor), options_(options) {
  if (sensor.azimuth_steps <= 0 || sensor.rotation_rate_hz <= 0.0 || sensor.max_range <= sensor.min_range) {
    throw std::invalid_argument("sensor '" + sensor.name + "': azimuth_steps, rotation_rate_hz and the range "
                                "limits must describe a working sensor");
  }
  if (options.dropout_probability < 0.0 || options.dropout_probability > 1.0) {
    throw std::invalid_argument("dropout probability must lie in [0, 1]");
  }
  if (options.detection_threshold < 0.0) throw std::invalid_argument("detection threshold must not be negative");
  if (options.foliage_depth < 0.0) throw std::invalid_argument("foliage depth must not be negative");
  if (options.mixed_pixel_probability < 0.0 || options.mixed_pixel_probability > 1.0) {
    throw std::invalid_argument("mixed pixel probability must lie in [0, 1]");
  }
  if (options.beam_range_bias < 0.0 || options.beam_elevation_error < 0.0) {
    throw std::invalid_argument("beam calibration errors must not be negative");
  }
  if (!(std::abs(options.range_offset) <= kMaxRangeOffset)) {
    throw std::invalid_argument("range offset must lie within +-1 m");
  }
  beams_ = drawBeams(sensor, options, unit_seed);
  if (beams_.empty()) throw std::invalid_argument("sensor '" + sensor.name + "' has no beams");
  // The head turns as the sensor config says, by default clockwise seen from above (as Velodyne and
  // Ouster sensors do) starting straight behind the vehicle: azimuth pi - 2 pi k / N, so that time grows
  // with the range image's column.
  const double start = sensor.sweep_start_azimuth_deg * M_PI / 180.0;
  const double turn = sensor.clockwise ? -1.0 : 1.0;
  for (int step = 0; step < sensor.azimuth_steps; ++step) {
    const double azimuth = start + turn * 2.0 * M_PI * step / sensor.azimuth_steps;
    azimuth_cos_.push_back(std::cos(azimuth));
    azimuth_sin_.push_back(std::sin(azimuth));
  }
  for (int step = 0; step < sensor.azimuth_steps; ++step) {
    for (int beam = 0; beam < beamCount(); ++beam) {
      hidden_by_vehicle_.push_back(hitsVehicle(actualDirection(beam, step)));
    }
  }
}

std::vector<Lidar::Beam> Lidar::drawBeams(const SensorConfig& sensor, const LidarOptions& options, uint64_t unit_seed) {
  // Drawn only when asked for, so that a perfectly calibrated sensor fires exactly along its table.
  const bool miscalibrated = options.beam_range_bias > 0.0 || options.beam_elevation_error > 0.0;
  Rng rng(unit_seed);
  std::vector<Beam> beams;
  const std::vector<float> elevations = beamElevations(sensor);
  const float middle = 0.5f * (*std::max_element(elevations.begin(), elevations.end()) +
                               *std::min_element(elevations.begin(), elevations.end()));
  for (const float table_elevation : elevations) {
    const double nominal = table_elevation;
    Beam beam;
    if (table_elevation < middle) beam.height = -options.lower_block_rise;
    beam.nominal = Eigen::Vector2d(std::cos(nominal), std::sin(nominal));
    double actual = nominal;
    beam.range_offset = options.range_offset;
    if (miscalibrated) {
      beam.range_offset += rng.gaussian(0.0, options.beam_range_bias);
      actual += rng.gaussian(0.0, options.beam_elevation_error * M_PI / 180.0);
    }
    beam.actual = Eigen::Vector2d(std::cos(actual), std::sin(actual));
    beams.push_back(beam);
  }
  return beams;
}

Eigen::Vector3d Lidar::direction(int beam, int step) const {
  return atAzimuth(beams_[beam].nominal, azimuth_cos_[step], azimuth_sin_[step]);
}

Eigen::Vector3d Lidar::actualDirection(int beam, int step) const {
  return atAzimuth(beams_[beam].actual, azimuth_cos_[step], azimuth_sin_[step]);
}

SimulatedScan Lidar::sweep(const RayCaster& scene, const std::function<Eigen::Isometry3d(double)>& sensor_pose_at,
                           double start, uint64_t seed) const {
  std::vector<Eigen::Isometry3d> poses;
  if (options_.deskewed) {
    poses.assign(1, sensor_pose_at(start));
  } else {
    poses.reserve(azimuthSteps());
    for (int step = 0; step < azimuthSteps(); ++step) poses.push_back(sensor_pose_at(start + firingTime(step)));
  }
  return addNoise(castAll(scene, poses), start, seed);
}

double Lidar::referenceOffset() const {
  const bool mid_sweep = !options_.deskewed && options_.time_convention == TimeConvention::azimuth;
  return mid_sweep ? 0.5 * sweepDuration() : 0.0;
}

std::vector<Lidar::Return> Lidar::castAll(const RayCaster& scene, const std::vector<Eigen::Isometry3d>& poses) const {
  const int beams = beamCount();
  std::vector<Return> returns(static_cast<size_t>(beams) * azimuthSteps());
  // Geometry only: exact, independent per ray, so the order the threads take them in does not matter.
  tbb::parallel_for(0, beams, [&](int beam) {
    for (int step = 0; step < azimuthSteps(); ++step) {
      const Eigen::Isometry3d& pose = poses.size() == 1 ? poses.front() : poses[step];
      if (hidden_by_vehicle_[static_cast<size_t>(step) * beams + beam]) continue;
      const Eigen::Vector3d local = actualDirection(beam, step);
      const Ray ray{pose * Eigen::Vector3d(0.0, 0.0, beams_[beam].height), pose.linear() * local};
      const auto hit = scene.cast(ray, sensor_.max_range);
      if (!hit || hit->reflectivity <= 0.0f) continue;  // sky, or glass that mirrors the beam away
      Return& result = returns[static_cast<size_t>(step) * beams + beam];
      result.range = hit->distance;
      // Lambertian: the echo weakens with the cosine of the angle between the beam and the surface.
      result.intensity = hit->reflectivity * static_cast<float>(std::abs(hit->normal.dot(ray.direction)));
      result.kind = hit->kind;
    }
  });
  return returns;
}

bool Lidar::hitsVehicle(const Eigen::Vector3d& direction) const {
  const Ray ray{Eigen::Vector3d::Zero(), direction};
  for (const Shape& part : options_.vehicle_body) {
    if (intersect(ray, part, 0.0, sensor_.max_range)) return true;
  }
  return false;
}

bool Lidar::detected(const Return& result, Rng& rng) const {
  if (options_.detection_threshold <= 0.0) return true;
  const double scale = kEchoReferenceRange / result.range;
  const double strength = result.intensity * scale * scale;
  return !rng.chance(std::exp(-strength / options_.detection_threshold));
}

bool Lidar::atDepthEdge(const Return& previous, const Return& result, const Return& next) {
  constexpr double kDepthEdge = 0.5;  // m
  // A wall seen at a grazing angle also changes range fast, but smoothly: as fast before as after.
  constexpr double kSmoothSlopeRatio = 4.0;
  if (next.range <= 0.0) return false;
  const double jump = std::abs(next.range - result.range);
  const bool smooth = previous.range > 0.0 && jump <= kSmoothSlopeRatio * std::abs(result.range - previous.range);
  return jump > kDepthEdge && !smooth;
}

double Lidar::clutteredRange(const Return& previous, const Return& result, const Return& next, Rng& rng) const {
  // Random numbers are drawn only for the clutter asked for: without it the sweep is what it always was.
  double range = result.range;
  if (options_.foliage_depth > 0.0 && result.kind == SurfaceKind::foliage) {
    range += std::min(-options_.foliage_depth * std::log(1.0 - rng.uniform()), 3.0 * options_.foliage_depth);
  }
  if (options_.mixed_pixel_probability > 0.0 && atDepthEdge(previous, result, next) &&
      rng.chance(options_.mixed_pixel_probability)) {
    range += rng.uniform() * (next.range - result.range);
  }
  return range;
}

SimulatedScan Lidar::addNoise(const std::vector<Return>& returns, double start, uint64_t seed) const {
  // One random stream in firing order: the same seed gives the same sweep whatever the thread count.
  Rng rng(seed);
  const int beams = beamCount();
  const bool with_times = !options_.deskewed && options_.time_convention == TimeConvention::field;
  SimulatedScan scan;
  scan.cloud.stamp = start + referenceOffset();
  for (int step = 0; step < azimuthSteps(); ++step) {
    for (int beam = 0; beam < beams; ++beam) {
      const Return& result = returns[static_cast<size_t>(step) * beams + beam];
      if (result.range <= 0.0 || !detected(result, rng) || rng.chance(options_.dropout_probability)) continue;
      const auto at = [&](int other_step) -> const Return& {
        return returns[static_cast<size_t>((other_step + azimuthSteps()) % azimuthSteps()) * beams + beam];
      };
      const Return& previous = at(step - 1);
      const Return& next = at(step + 1);
      const double range = clutteredRange(previous, result, next, rng) + beams_[beam].range_offset +
                           rng.gaussian(0.0, sensor_.range_noise_stddev);
      if (range < sensor_.min_range || range > sensor_.max_range) continue;
      scan.cloud.points.push_back((range * direction(beam, step)).cast<float>());
      scan.cloud.intensity.push_back(result.intensity);
      scan.cloud.ring.push_back(static_cast<uint16_t>(ringOfBeam(sensor_, beam)));
      if (with_times) scan.cloud.time.push_back(static_cast<float>(firingTime(step)));
      scan.surface.push_back(result.kind);
    }
  }
  return scan;
}

}  // namespace elo::sim
