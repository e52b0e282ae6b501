#include "elo/sim/simulation.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "elo/sim/rng.hpp"

namespace elo::sim {
namespace {

// Apart from the world's streams (see world.cpp).
constexpr uint64_t kNoiseStream = 4;
constexpr uint64_t kCalibrationStream = 5;  // the sequence's seed also picks the unit
constexpr double kReachMargin = 10.0;  // m of world beyond the sensor's range

Route routeFor(const SimulationSpec& spec) {
  const double frame_period = 1.0 / spec.config.sensor.rotation_rate_hz;
  if (spec.driven_poses.empty()) {
    // One sweep past the last frame's start, for the poses inside its sweep.
    const double duration = (spec.frames + 1) * frame_period;
    return proceduralRoute(spec.trajectory, cruiseSpeed(spec.world), duration);
  }
  if (spec.driven_poses.size() < static_cast<size_t>(spec.frames)) {
    throw std::invalid_argument("the driven trajectory has " + std::to_string(spec.driven_poses.size()) +
                                " poses, fewer than the " + std::to_string(spec.frames) + " frames asked for");
  }
  const size_t used = std::min(spec.driven_poses.size(), static_cast<size_t>(spec.frames) + 1);
  return routeFromPoses({spec.driven_poses.begin(), spec.driven_poses.begin() + used}, frame_period);
}

// The reflection y -> -y, its own inverse.
Eigen::Isometry3d mirrorOf(const Eigen::Isometry3d& pose) {
  const Eigen::Matrix3d flip = Eigen::Vector3d(1.0, -1.0, 1.0).asDiagonal();
  Eigen::Isometry3d mirrored = Eigen::Isometry3d::Identity();
  mirrored.linear() = flip * pose.linear() * flip;
  mirrored.translation() = flip * pose.translation();
  return mirrored;
}

}  // namespace

Simulation::Simulation(const SimulationSpec& spec)
    : spec_(spec), lidar_(spec.config.sensor, spec.lidar, mixSeed(spec.seed, kCalibrationStream)) {
  if (spec.frames <= 0) throw std::invalid_argument("a simulation needs at least one frame");
  if (spec.mirrored && !spec.lidar.deskewed && spec.lidar.time_convention == TimeConvention::azimuth) {
    throw std::invalid_argument("a mirrored drive cannot tell its times by azimuth: the sensor turns the other way");
  }
  const Route route = routeFor(spec);
  world_ = std::make_unique<World>(spec.world, route,
                                   WorldOptions{spec.seed, spec.config.sensor.max_range + kReachMargin, spec.moving_cars});
  trajectory_ = std::make_unique<SensorTrajectory>(route, world_->ground(), spec.config.ground.sensor_height,
                                                   VehicleGeometry{}, spec.gait);
}

double Simulation::sweepStart(int frame) const { return frame / spec_.config.sensor.rotation_rate_hz; }

double Simulation::stamp(int frame) const { return sweepStart(frame) + lidar_.referenceOffset(); }

double Simulation::recordedStamp(int frame) const {
  const double rounding = spec_.stamp_rounding;
  return rounding > 0.0 ? std::round(stamp(frame) / rounding) * rounding : stamp(frame);
}

Eigen::Isometry3d Simulation::sensorPose(int frame) const { return poseAt(stamp(frame)); }

Eigen::Isometry3d Simulation::recordedTruth(int frame) const {
  const double instant = spec_.truth_at_recorded_stamps ? recordedStamp(frame) : stamp(frame);
  return poseAt(instant + spec_.truth_time_offset);
}

Eigen::Isometry3d Simulation::poseAt(double time) const {
  const Eigen::Isometry3d pose = trajectory_->poseAt(time);
  return spec_.mirrored ? mirrorOf(pose) : pose;
}

SimulatedScan Simulation::scan(int frame) const {
  const double start = sweepStart(frame);
  const Eigen::Isometry3d pose = trajectory_->poseAt(start);
  // Moving cars stand where they are at the sweep's start; they move a metre or two during it.
  const auto snapshot = world_->snapshot(start, pose.translation(), spec_.config.sensor.max_range + kReachMargin);
  // An instantaneous sweep comes without per-point times (Lidar::sweep): the odometry
  // (deskew.time_source field) would move its points by them.
  SimulatedScan scan = lidar_.sweep(*snapshot, [this](double time) { return trajectory_->poseAt(time); }, start,
                                    mixSeed(spec_.seed, kNoiseStream, static_cast<uint64_t>(frame)));
  if (spec_.mirrored) {
    for (Vec3f& point : scan.cloud.points) point.y() = -point.y();
  }
  scan.cloud.stamp = recordedStamp(frame);
  return scan;
}

}  // namespace elo::sim
