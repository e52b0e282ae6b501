// Exact scans of analytic scenes for the core tests: a flat ground plane and axis-aligned boxes, hit by
// the beams of a configured sensor from a known pose. Every return lies exactly on a known surface, so
// the tests can check labels, normals and poses against the truth.
#pragma once

#include <Eigen/Geometry>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "elo/config.hpp"
#include "elo/se3.hpp"
#include "elo/sensor/sensor_model.hpp"
#include "elo/types.hpp"

namespace elo::test {

// A pose from a translation and roll, pitch, yaw in degrees (applied x, then y, then z).
inline Eigen::Isometry3d pose(double x, double y, double z, double roll_deg, double pitch_deg, double yaw_deg) {
  const double d = M_PI / 180.0;
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = (Eigen::AngleAxisd(yaw_deg * d, Eigen::Vector3d::UnitZ()) *
                Eigen::AngleAxisd(pitch_deg * d, Eigen::Vector3d::UnitY()) *
                Eigen::AngleAxisd(roll_deg * d, Eigen::Vector3d::UnitX()))
                   .toRotationMatrix();
  T.translation() << x, y, z;
  return T;
}

struct Box {
  Eigen::Vector3d min;
  Eigen::Vector3d max;
};

enum class Surface { none, ground, box };

struct Hit {
  double range = std::numeric_limits<double>::infinity();
  Surface surface = Surface::none;
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();  // world frame
  const Box* box = nullptr;
};

// Distance from a point on a face of `box` to the nearest edge of that face, or from a ground point to
// the nearest box footprint: near an edge the local surface is two planes and no normal is "the" true one.
inline double distanceToFaceEdge(const Box& box, const Eigen::Vector3d& point, const Eigen::Vector3d& normal) {
  double distance = std::numeric_limits<double>::infinity();
  for (int axis = 0; axis < 3; ++axis) {
    if (normal[axis] != 0.0) continue;
    distance = std::min({distance, point[axis] - box.min[axis], box.max[axis] - point[axis]});
  }
  return distance;
}

struct Scene {
  double ground_z = -1.73;
  std::vector<Box> boxes;

  Hit cast(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction) const {
    Hit best;
    if (direction.z() < 0.0) {
      const double t = (ground_z - origin.z()) / direction.z();
      if (t > 0.0) best = {t, Surface::ground, Eigen::Vector3d::UnitZ(), nullptr};
    }
    for (const Box& box : boxes) castBox(box, origin, direction, best);
    return best;
  }

  // Slab test: the entry face of the ray into the box.
  static void castBox(const Box& box, const Eigen::Vector3d& origin, const Eigen::Vector3d& direction, Hit& best) {
    double enter = -std::numeric_limits<double>::infinity();
    double leave = std::numeric_limits<double>::infinity();
    int enter_axis = -1;
    for (int axis = 0; axis < 3; ++axis) {
      if (std::abs(direction[axis]) < 1e-12) {
        if (origin[axis] < box.min[axis] || origin[axis] > box.max[axis]) return;
        continue;
      }
      double t0 = (box.min[axis] - origin[axis]) / direction[axis];
      double t1 = (box.max[axis] - origin[axis]) / direction[axis];
      if (t0 > t1) std::swap(t0, t1);
      if (t0 > enter) {
        enter = t0;
        enter_axis = axis;
      }
      leave = std::min(leave, t1);
    }
    if (enter_axis < 0 || enter > leave || enter <= 0.0 || enter >= best.range) return;
    Eigen::Vector3d normal = Eigen::Vector3d::Zero();
    normal[enter_axis] = direction[enter_axis] > 0.0 ? -1.0 : 1.0;
    best = {enter, Surface::box, normal, &box};
  }
};

inline double distanceToFootprints(const std::vector<Box>& boxes, const Eigen::Vector3d& point) {
  double distance = std::numeric_limits<double>::infinity();
  for (const Box& box : boxes) {
    const double dx = std::max({box.min.x() - point.x(), 0.0, point.x() - box.max.x()});
    const double dy = std::max({box.min.y() - point.y(), 0.0, point.y() - box.max.y()});
    distance = std::min(distance, std::hypot(dx, dy));
  }
  return distance;
}

struct ScanWithTruth {
  PointCloud cloud;
  std::vector<Surface> surface;          // per point
  std::vector<Eigen::Vector3d> normal;   // per point, sensor frame
  std::vector<double> edge_distance;     // per point: to the nearest edge of its face or box footprint
  std::vector<int> step;                 // per point: the azimuth step that fired it
};

// Gaussian samples from the raw output of a fixed generator (Box-Muller), so the same seed gives the
// same noise with every standard library.
class GaussianNoise {
 public:
  explicit GaussianNoise(uint32_t seed) : engine_(seed) {}
  double operator()() {
    const double u1 = (static_cast<double>(engine_()) + 1.0) / 4294967296.0;
    const double u2 = static_cast<double>(engine_()) / 4294967296.0;
    return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * M_PI * u2);
  }

 private:
  std::mt19937 engine_;
};

// Fires every beam of `sensor` at `azimuth_steps` azimuths, clockwise from straight behind, step k from
// `world_from_sensor_at(k)`, adding Gaussian range noise of `range_noise` metres.
template <typename PoseOfStep>
ScanWithTruth scanSceneFrom(const Scene& scene, const SensorConfig& sensor, const PoseOfStep& world_from_sensor_at,
                            double stamp, double range_noise, uint32_t seed) {
  ScanWithTruth scan;
  GaussianNoise noise(seed);
  scan.cloud.stamp = stamp;
  const std::vector<float> elevations = beamElevations(sensor);
  for (int step = 0; step < sensor.azimuth_steps; ++step) {
    const Eigen::Isometry3d world_from_sensor = world_from_sensor_at(step);
    const Eigen::Matrix3d rotation = world_from_sensor.linear();
    const double azimuth = M_PI - 2.0 * M_PI * (step + 0.5) / sensor.azimuth_steps;
    for (size_t beam = 0; beam < elevations.size(); ++beam) {
      const double elevation = elevations[beam];
      const Eigen::Vector3d local(std::cos(elevation) * std::cos(azimuth), std::cos(elevation) * std::sin(azimuth),
                                  std::sin(elevation));
      const Hit hit = scene.cast(world_from_sensor.translation(), rotation * local);
      if (hit.surface == Surface::none || hit.range > sensor.max_range || hit.range < sensor.min_range) continue;
      const double range = hit.range + (range_noise > 0.0 ? range_noise * noise() : 0.0);
      scan.cloud.points.push_back((local * range).cast<float>());
      scan.cloud.ring.push_back(static_cast<uint16_t>(ringOfBeam(sensor, static_cast<int>(beam))));
      scan.step.push_back(step);
      scan.surface.push_back(hit.surface);
      scan.normal.push_back(rotation.transpose() * hit.normal);
      const Eigen::Vector3d world_point = world_from_sensor.translation() + rotation * local * hit.range;
      scan.edge_distance.push_back(hit.box ? distanceToFaceEdge(*hit.box, world_point, hit.normal)
                                           : distanceToFootprints(scene.boxes, world_point));
    }
  }
  return scan;
}

// An instantaneous scan from `world_from_sensor`.
inline ScanWithTruth scanScene(const Scene& scene, const SensorConfig& sensor,
                               const Eigen::Isometry3d& world_from_sensor, double stamp = 0.0,
                               double range_noise = 0.0, uint32_t seed = 1) {
  return scanSceneFrom(scene, sensor, [&](int) { return world_from_sensor; }, stamp, range_noise, seed);
}

// The firing time of azimuth step `step` relative to mid-sweep, the reference instant of KITTI's HDL-64E
// (clockwise from straight behind, sensor.rotation_rate_hz).
inline double firingTime(const SensorConfig& sensor, int step) {
  return ((step + 0.5) / sensor.azimuth_steps - 0.5) / sensor.rotation_rate_hz;
}

// A sweep from a sensor moving at the constant twist `velocity` (per second; translation, rotation; in
// its frame at the reference instant): step k fires from world_from_reference * exp(t_k velocity), at
// t_k = firingTime(k), which every point carries in `time`.
inline ScanWithTruth sweepScene(const Scene& scene, const SensorConfig& sensor,
                                const Eigen::Isometry3d& world_from_reference, const Vector6d& velocity,
                                double stamp = 0.0) {
  ScanWithTruth scan = scanSceneFrom(
      scene, sensor, [&](int step) { return world_from_reference * expSE3(firingTime(sensor, step) * velocity); },
      stamp, 0.0, 1);
  for (int step : scan.step) scan.cloud.time.push_back(static_cast<float>(firingTime(sensor, step)));
  return scan;
}

// A sensor turning about a fixed `axis` (unit, its frame), the angle `angle(t)` at `t` seconds from an
// instant, while it slides at `linear` m/s in that instant's frame: the motion of a handheld sensor swung
// at a rate that changes within a sweep, which a constant twist cannot follow and a gyro can.
template <typename Angle>
struct Swing {
  Eigen::Vector3d axis;
  Angle angle;
  Eigen::Vector3d linear;

  // The sensor's frame at `t` in its frame at the instant.
  Eigen::Isometry3d at(double t) const {
    Eigen::Isometry3d frame = Eigen::Isometry3d::Identity();
    frame.linear() = Eigen::AngleAxisd(angle(t), axis).toRotationMatrix();
    frame.translation() = linear * t;
    return frame;
  }
};

// A sweep of a sensor swung by `swing` about its reference instant, at `world_from_reference` then:
// step k fires from world_from_reference * swing.at(t_k), t_k = firingTime(k), which every point
// carries in `time`.
template <typename Angle>
ScanWithTruth swungSweepScene(const Scene& scene, const SensorConfig& sensor,
                              const Eigen::Isometry3d& world_from_reference, const Swing<Angle>& swing,
                              double stamp = 0.0) {
  ScanWithTruth scan = scanSceneFrom(
      scene, sensor, [&](int step) { return world_from_reference * swing.at(firingTime(sensor, step)); }, stamp, 0.0,
      1);
  for (int step : scan.step) scan.cloud.time.push_back(static_cast<float>(firingTime(sensor, step)));
  return scan;
}

// A street: ground, facades on both sides with gaps, a wall across the end and parked boxes, so that
// all six degrees of freedom are constrained.
inline Scene streetScene() {
  Scene scene;
  scene.boxes = {
      {{-60, 8, -1.73}, {-5, 9, 12}},      {{0, 8, -1.73}, {37, 9, 12}},       // left facades, gap
      {{-60, -9, -1.73}, {10, -8, 10}},    {{14, -9, -1.73}, {37, -8, 10}},    // right facades, gap
      {{40, -12, -1.73}, {41, 12, 8}},                                         // wall across the street
      {{6, 4, -1.73}, {10.5, 5.8, -0.3}},  {{-12, -6, -1.73}, {-7.5, -4.2, -0.2}},  // parked cars
      {{20, 3, -1.73}, {20.3, 3.3, 3.0}},  {{-20, -3, -1.73}, {-19.7, -2.7, 3.0}},  // poles
  };
  return scene;
}

}  // namespace elo::test
