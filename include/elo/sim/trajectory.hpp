// Where the vehicle drives: a Route is its path over the ground plane with its timing (procedural, or
// taken from a KITTI poses file); a SensorTrajectory stands the vehicle on the world's ground, so the
// sensor's height, pitch and roll are those of the simulated road and the ground truth written out is
// the motion that was actually simulated.
#pragma once

#include <Eigen/Geometry>
#include <optional>
#include <string>
#include <vector>

#include "elo/sim/gait.hpp"
#include "elo/sim/ground.hpp"

namespace elo::sim {

struct Pose2 {
  double x = 0.0;
  double y = 0.0;
  double heading = 0.0;  // rad, counter-clockwise from +x
};

// A raised-cosine hill (negative height: a valley) that a route asks the world's terrain to carry.
struct Hill {
  Eigen::Vector2d center = Eigen::Vector2d::Zero();
  double radius = 100.0;
  double height = 10.0;
  double heightAt(const Eigen::Vector2d& point) const;
};

class Route {
 public:
  // Samples in time order; headings may wrap, they are unwrapped here.
  Route(std::vector<double> times, std::vector<Pose2> poses, std::vector<Hill> hills = {});

  Pose2 at(double time) const;  // linear between samples, clamped at the ends
  double startTime() const { return times_.front(); }
  double endTime() const { return times_.back(); }
  // The driven path as points at least `spacing` apart: the road the world is built along.
  std::vector<Eigen::Vector2d> path(double spacing) const;
  const std::vector<Hill>& hills() const { return hills_; }

 private:
  std::vector<double> times_;
  std::vector<Pose2> poses_;
  std::vector<Hill> hills_;
};

// `loop` laps a closed circuit at cruise speed from the first frame, each lap the same in place and
// time: a sequence of exactly one lap replayed end to end is one continuous drive (the soak test).
// `hard_driving`: a car driven hard through town: braking at 0.8 g to a stop every
// ~100 m, accelerating at 3 m/s^2, and turning corners of 7-12 m radius at 5 m/s^2 of lateral acceleration
// (up to 45 deg/s of yaw at 6-8 m/s).
enum class TrajectoryKind { straight, curves, roundabout, hill, stop_and_go, uturn, loop, hard_driving };

std::optional<TrajectoryKind> trajectoryKindFromName(const std::string& name);
std::string trajectoryName(TrajectoryKind kind);
std::vector<std::string> trajectoryNames();

// A drive of `duration` seconds along the kind's road: from rest (the loop: already at speed) up to
// `cruise_speed` (m/s), slowing for turns to a comfortable lateral acceleration, and stopping for a
// few seconds every ~150 m in stop-and-go.
Route proceduralRoute(TrajectoryKind kind, double cruise_speed, double duration);

// Seconds per lap of the `loop` circuit at `cruise_speed`: a whole number, so that a lap is a whole
// number of frames at any integer frame rate (urban, 10 m/s: 40 s, 400 frames at 10 Hz).
double loopLapDuration(double cruise_speed);

// A drive through given LiDAR-frame poses, one per frame `frame_period` apart: x, y and heading are
// theirs; height, pitch and roll come from the ground the route is placed on.
Route routeFromPoses(const std::vector<Eigen::Isometry3d>& lidar_poses, double frame_period);

// The velodyne->camera calibration `Tr` of KITTI odometry sequences 00-02.
Eigen::Isometry3d kittiVeloToCam00();

struct VehicleGeometry {
  double wheelbase = 2.7;  // m, front to rear axle: sets pitch on slopes and bumps
  double track = 1.6;      // m, left to right wheel: sets roll
};

// The route with the vehicle standing on `ground` (which must outlive it): the sensor sits
// `sensor_height` straight above the ground under it, tilted with the plane through the wheels.
class SensorTrajectory {
 public:
  // `gait`: how the sensor moves about the route's pose (gait.hpp); none for a vehicle.
  SensorTrajectory(const Route& route, const GroundSurface& ground, double sensor_height,
                   VehicleGeometry vehicle = {}, Gait gait = {});

  Eigen::Isometry3d poseAt(double time) const;  // sensor in the world frame
  const Route& route() const { return route_; }

 private:
  Route route_;
  const GroundSurface& ground_;
  double sensor_height_;
  VehicleGeometry vehicle_;
  Gait gait_;
};

}  // namespace elo::sim
