// Two drives through one simulated world, for localization: the drive a map is made of, and other drives
// (another lane, a later start, other noise, another sensor unit or model, moving cars) localized in
// it, each with its exact ground truth in the world frame, which is the map's.
#pragma once

#include <tbb/parallel_for.h>

#include <Eigen/Geometry>
#include <cmath>
#include <functional>
#include <map>
#include <memory>
#include <unordered_map>
#include <vector>

#include "elo/config.hpp"
#include "elo/map/point_map.hpp"
#include "elo/sim/lidar.hpp"
#include "elo/sim/rng.hpp"
#include "elo/sim/trajectory.hpp"
#include "elo/sim/world.hpp"

namespace elo::test {

constexpr double kFramePeriod = 0.1;  // s: every simulated sensor turns at 10 Hz

// A world built along a procedural route of `duration` seconds. Its reach covers the farthest sensor.
class SharedWorld {
 public:
  SharedWorld(sim::WorldFamily family, sim::TrajectoryKind kind, double duration, uint64_t seed, int moving_cars = 0)
      : route_(sim::proceduralRoute(kind, sim::cruiseSpeed(family), duration)),
        world_(family, route_, sim::WorldOptions{seed, 130.0, moving_cars}) {}

  const sim::Route& route() const { return route_; }
  const sim::World& world() const { return world_; }

 private:
  sim::Route route_;
  sim::World world_;
};

// Where a drive goes in the shared world: the route from `start` seconds on, `lateral` metres to its left.
struct DrivePlan {
  double start = 0.0;
  double lateral = 0.0;
  uint64_t noise_seed = 1;
  uint64_t unit_seed = 1;  // the sensor unit's calibration errors
};

// The route of `plan`: the shared route's samples from its start, shifted sideways.
inline sim::Route shiftedRoute(const sim::Route& route, const DrivePlan& plan) {
  std::vector<double> times;
  std::vector<sim::Pose2> poses;
  constexpr double kSample = 0.02;
  for (double t = route.startTime() + plan.start; t <= route.endTime(); t += kSample) {
    sim::Pose2 pose = route.at(t);
    pose.x -= plan.lateral * std::sin(pose.heading);
    pose.y += plan.lateral * std::cos(pose.heading);
    times.push_back(t - route.startTime() - plan.start);
    poses.push_back(pose);
  }
  return sim::Route(times, poses, route.hills());
}

// One sensor driving a plan through the shared world, its sweeps instantaneous (no motion distortion)
// unless `lidar.deskewed` is false.
class Drive {
 public:
  Drive(const SharedWorld& world, const Config& config, const DrivePlan& plan, sim::LidarOptions lidar = {})
      : world_(world),
        plan_(plan),
        lidar_(config.sensor, lidar, plan.unit_seed),
        trajectory_(shiftedRoute(world.route(), plan), world.world().ground(), config.ground.sensor_height),
        radius_(config.sensor.max_range + 10.0) {}

  // The scan of `frame`, stamped at its reference instant.
  PointCloud scan(int frame) const {
    const double start = frame * kFramePeriod;
    const Eigen::Isometry3d pose = trajectory_.poseAt(start);
    // The traffic runs on the shared world's clock, so that another drive meets other cars.
    const auto snapshot = world_.world().snapshot(start + plan_.start, pose.translation(), radius_);
    return lidar_
        .sweep(*snapshot, [this](double time) { return trajectory_.poseAt(time); }, start,
               sim::mixSeed(plan_.noise_seed, static_cast<uint64_t>(frame)))
        .cloud;
  }
  // The sensor in the world (the map frame) at the scan's stamp.
  Eigen::Isometry3d pose(int frame) const { return trajectory_.poseAt(frame * kFramePeriod + lidar_.referenceOffset()); }
  int frameCount() const {
    return static_cast<int>(std::floor((trajectory_.route().endTime() - 2.0 * kFramePeriod) / kFramePeriod));
  }

 private:
  const SharedWorld& world_;
  DrivePlan plan_;
  sim::Lidar lidar_;
  sim::SensorTrajectory trajectory_;
  double radius_;
};

// The map's points that lie more than `metres` ahead of `pose` (along its x axis): the map of a drive that
// began further along the road.
inline MapCloud mapAheadOf(const MapCloud& map, const Eigen::Isometry3d& pose, double metres) {
  const Eigen::Vector3f origin = pose.translation().cast<float>();
  const Eigen::Vector3f forward = pose.rotation().col(0).cast<float>();
  MapCloud ahead;
  for (size_t i = 0; i < map.size(); ++i) {
    if ((map.points[i] - origin).dot(forward) <= metres) continue;
    ahead.points.push_back(map.points[i]);
    ahead.normals.push_back(map.normals[i]);
    if (!map.intensity.empty()) ahead.intensity.push_back(map.intensity[i]);
  }
  return ahead;
}

// A scan and the sensor's true pose at its stamp, in the map's frame.
using PlacedScan = std::function<std::pair<PointCloud, Eigen::Isometry3d>(int frame)>;

// The map of scans placed at their true poses (every `every`-th of `frames`), one point per `voxel` (the
// centroid of the points that fell in it), normals estimated as a loaded map without them gets.
inline MapCloud mapOfScans(const PlacedScan& scan_at, int frames, int every, double voxel, double normal_radius) {
  struct Voxel {
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    int count = 0;
  };
  std::vector<int> chosen;
  for (int frame = 0; frame < frames; frame += every) chosen.push_back(frame);
  std::vector<std::vector<Vec3f>> placed(chosen.size());
  tbb::parallel_for(size_t{0}, chosen.size(), [&](size_t i) {
    const auto [cloud, truth] = scan_at(chosen[i]);
    const Eigen::Isometry3f pose = truth.cast<float>();
    for (const Vec3f& point : cloud.points) placed[i].push_back(pose * point);
  });
  std::unordered_map<uint64_t, Voxel> voxels;
  const auto key = [voxel](const Vec3f& point) {
    const Eigen::Vector3i cell = (point.cast<double>() / voxel).array().floor().cast<int>();
    const auto bits = [](int value) { return static_cast<uint64_t>(value + (1 << 20)) & 0x1FFFFF; };
    return bits(cell.x()) | (bits(cell.y()) << 21) | (bits(cell.z()) << 42);
  };
  for (const auto& points : placed) {
    for (const Vec3f& point : points) {
      Voxel& cell = voxels[key(point)];
      cell.sum += point.cast<double>();
      ++cell.count;
    }
  }
  MapCloud map;
  for (const auto& [unused, cell] : voxels) map.points.push_back((cell.sum / cell.count).cast<float>());
  prepareMap(map, normal_radius);
  return map;
}

inline MapCloud mapOfDrive(const Drive& drive, int frames, int every, double voxel, double normal_radius) {
  return mapOfScans([&drive](int frame) { return std::make_pair(drive.scan(frame), drive.pose(frame)); }, frames,
                    every, voxel, normal_radius);
}

}  // namespace elo::test
