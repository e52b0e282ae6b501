// The simulator assembled: a world built along a route, the vehicle standing on its ground, and the
// LiDAR sweeping it once per frame.
#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <memory>
#include <vector>

#include "elo/config.hpp"
#include "elo/sim/lidar.hpp"
#include "elo/sim/trajectory.hpp"
#include "elo/sim/world.hpp"

namespace elo::sim {

struct SimulationSpec {
  WorldFamily world = WorldFamily::urban;
  TrajectoryKind trajectory = TrajectoryKind::straight;
  // When not empty, the vehicle drives through these LiDAR-frame poses (one per frame, e.g. KITTI
  // ground truth) instead of the procedural `trajectory`.
  std::vector<Eigen::Isometry3d> driven_poses;
  int frames = 100;
  uint64_t seed = 1;
  Config config;  // the sensor, and ground.sensor_height for its mounting height
  LidarOptions lidar;
  int moving_cars = 0;
  // The drive in the world's mirror image (y -> -y, seen by a sensor that turns the other way): a left
  // turn becomes a right one, with the same noise on the mirrored returns. The pipeline owes both the
  // same drift with the opposite heading error (SparseSensors.*). Not with the azimuth time convention,
  // whose times are read from the turning direction.
  bool mirrored = false;
  // How the sensor moves about the route's pose: carried by hand, on a legged robot (gait.hpp); none for
  // a vehicle.
  Gait gait;
  // Seconds the scans' recorded stamps are rounded to (0: exact), as KITTI-raw's times.txt rounds them to
  // 10 ms: the scans are still taken a sweep apart, and the ground truth is at the true instants unless
  // truth_at_recorded_stamps.
  double stamp_rounding = 0.0;
  // The recorded ground truth taken at each scan's recorded (rounded) stamp instead of its true instant,
  // as KITTI-raw's OXTS poses are the 100 Hz samples at its rounded stamps: up to half the rounding of
  // travel off the scan (docs/real_drives.md).
  bool truth_at_recorded_stamps = false;
  // Seconds by which the recorded ground truth is taken after each scan's stamp (0: at it), as KITTI-raw's
  // OXTS poses are off the scans' stamps (about -12 ms on drive 0005, docs/real_drives.md): a turn of
  // w rad/s then reads as w times this of rotation error at each end of a segment. Clamped to the drive.
  double truth_time_offset = 0.0;
};

class Simulation {
 public:
  // Throws std::invalid_argument for a spec that cannot be simulated (no frames, fewer driven poses
  // than frames, an unusable sensor).
  explicit Simulation(const SimulationSpec& spec);

  int frameCount() const { return spec_.frames; }
  double sweepStart(int frame) const;  // s; frame 0's sweep starts at 0
  // The frame's reference instant (s): its scan's stamp, the sweep's start but for a sweep with motion
  // in the azimuth convention, whose reference is mid-sweep (Lidar::referenceOffset).
  double stamp(int frame) const;
  // The stamp the frame's scan is recorded with: stamp(), rounded to SimulationSpec::stamp_rounding.
  double recordedStamp(int frame) const;
  Eigen::Isometry3d sensorPose(int frame) const;  // in the world frame, at the frame's reference instant
  // The ground truth the frame is recorded with: the sensor's pose SimulationSpec::truth_time_offset after
  // its reference instant, or after its recorded stamp with SimulationSpec::truth_at_recorded_stamps, in
  // the world frame.
  Eigen::Isometry3d recordedTruth(int frame) const;
  SimulatedScan scan(int frame) const;

  const World& world() const { return *world_; }
  const Lidar& lidar() const { return lidar_; }
  const SensorTrajectory& trajectory() const { return *trajectory_; }

 private:
  Eigen::Isometry3d poseAt(double time) const;  // mirrored with the drive

  SimulationSpec spec_;
  Lidar lidar_;
  std::unique_ptr<World> world_;
  std::unique_ptr<SensorTrajectory> trajectory_;
};

}  // namespace elo::sim
