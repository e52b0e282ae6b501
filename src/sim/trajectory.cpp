#include "elo/sim/trajectory.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <stdexcept>

namespace elo::sim {
namespace {

constexpr double kLateralAcceleration = 2.0;  // m/s^2: comfortable cornering
constexpr double kAcceleration = 1.5;         // m/s^2
constexpr double kDeceleration = 2.5;         // m/s^2
constexpr double kArcStep = 0.05;             // m of path between route samples
constexpr double kCurvatureRamp = 6.0;        // m over which curvature changes, as a clothoid would
constexpr double kStopDuration = 3.0;         // s standing at each stop of stop-and-go
constexpr double kLoopMinStraight = 40.0;     // m: the shortest straight of the loop circuit

struct Piece {
  double length;
  double curvature;
};

Piece straight(double length) { return {length, 0.0}; }

// A turn by `degrees` (positive: left) on a circle of `radius`.
Piece turn(double degrees, double radius) {
  return {std::abs(degrees) * M_PI / 180.0 * radius, std::copysign(1.0 / radius, degrees)};
}

// A road as a cycle of pieces repeated for as long as the drive needs.
// How hard the vehicle is driven, m/s^2.
struct DrivingLimits {
  double lateral = kLateralAcceleration;
  double acceleration = kAcceleration;
  double deceleration = kDeceleration;
};

struct RoadDesign {
  std::vector<Piece> cycle;
  double stop_spacing = 0.0;  // m between stops; 0: no stops
  bool hills = false;
  // The cycle is a closed circuit driven at cruise speed from the first frame: every lap retraces the
  // first exactly, in place and in time.
  bool closed_circuit = false;
  DrivingLimits limits = DrivingLimits();
};

// A car driven hard through town: 0.8 g of braking, 3 m/s^2 of acceleration, 5 m/s^2 in the corners,
// which are a town's (7-12 m radius), and a stop every 100 m: fast turns at low speed.
RoadDesign hardDrivingDesign() {
  RoadDesign design;
  design.cycle = {straight(45.0), turn(90, 10.0), straight(35.0), turn(-90, 7.0), straight(60.0), turn(120, 12.0),
                  straight(30.0), turn(-60, 8.0), straight(40.0), turn(-150, 9.0)};
  design.stop_spacing = 100.0;
  design.limits = {5.0, 3.0, 0.8 * 9.81};
  return design;
}

// The turn radius the vehicle takes at cruise speed: tighter in town, wider on the highway.
double comfortableRadius(double cruise_speed) {
  return std::max(30.0, cruise_speed * cruise_speed / kLateralAcceleration);
}

double cycleLength(const RoadDesign& design) {
  double length = 0.0;
  for (const Piece& piece : design.cycle) length += piece.length;
  return length;
}

// A stadium: two straights and two half turns, starting halfway along a straight so that the seam
// between laps lies on a straight. The straights make the lap last a whole number of seconds.
RoadDesign loopDesign(double cruise_speed) {
  const double radius = comfortableRadius(cruise_speed);
  const double turns = 2.0 * M_PI * radius;
  const double straight_length = 0.5 * (loopLapDuration(cruise_speed) * cruise_speed - turns);
  RoadDesign design;
  design.cycle = {straight(0.5 * straight_length), turn(180, radius), straight(straight_length), turn(180, radius),
                  straight(0.5 * straight_length)};
  design.closed_circuit = true;
  return design;
}

RoadDesign designFor(TrajectoryKind kind, double cruise_speed) {
  const double radius = comfortableRadius(cruise_speed);
  switch (kind) {
    case TrajectoryKind::straight:
      return {{straight(1000.0)}};
    case TrajectoryKind::curves:
      // Net heading change 0 per cycle: a winding road that keeps its general direction.
      return {{straight(1.2 * radius), turn(60, radius), straight(0.8 * radius), turn(-90, radius),
               straight(1.2 * radius), turn(30, radius)}};
    case TrajectoryKind::roundabout:
      // Swerve right into the ring, three-eighths round it anticlockwise, swerve out: a left turn
      // through the roundabout. Four of them close a square, so later laps revisit the same streets.
      return {{straight(100.0), turn(-30, 20.0), turn(150, 15.0), turn(-30, 20.0)}};
    case TrajectoryKind::hill:
      return {{straight(250.0), turn(25, 3.0 * radius), straight(250.0), turn(-25, 3.0 * radius)}, 0.0, true};
    case TrajectoryKind::stop_and_go:
      return {{straight(150.0), turn(20, 2.0 * radius), straight(150.0), turn(-20, 2.0 * radius)}, 150.0};
    case TrajectoryKind::uturn:
      // Out, turn back on a tight circle, return beside the outbound leg, turn again: laps of a loop.
      return {{straight(150.0), turn(180, 8.0), straight(150.0), turn(180, 8.0)}};
    case TrajectoryKind::loop:
      return loopDesign(cruise_speed);
    case TrajectoryKind::hard_driving:
      return hardDrivingDesign();
  }
  throw std::invalid_argument("unknown trajectory kind");
}

// Curvature every kArcStep along `length` metres of the design, eased over kCurvatureRamp so that
// the steering (and so the yaw rate) changes gradually; the moving average keeps each turn's angle.
std::vector<double> curvatureProfile(const RoadDesign& design, double length) {
  const size_t samples = static_cast<size_t>(std::ceil(length / kArcStep)) + 1;
  std::vector<double> raw(samples);
  size_t piece = 0;
  double piece_end = design.cycle[0].length;
  for (size_t i = 0; i < samples; ++i) {
    const double arc = i * kArcStep;
    while (arc >= piece_end) {
      piece = (piece + 1) % design.cycle.size();
      piece_end += design.cycle[piece].length;
    }
    raw[i] = design.cycle[piece].curvature;
  }
  const int half_window = static_cast<int>(std::round(0.5 * kCurvatureRamp / kArcStep));
  std::vector<double> prefix(samples + 1, 0.0);
  for (size_t i = 0; i < samples; ++i) prefix[i + 1] = prefix[i] + raw[i];
  std::vector<double> eased(samples);
  for (size_t i = 0; i < samples; ++i) {
    const size_t begin = i >= static_cast<size_t>(half_window) ? i - half_window : 0;
    const size_t end = std::min(samples, i + half_window + 1);
    eased[i] = (prefix[end] - prefix[begin]) / static_cast<double>(end - begin);
  }
  return eased;
}

// Scales the curvature so that each lap of a closed circuit turns exactly 360 deg. Sampling every
// kArcStep rounds each turn to a whole number of samples, which would leave the lap a fraction of a
// degree open and the laps drifting apart.
void closeLaps(const RoadDesign& design, std::vector<double>& curvature) {
  const size_t lap_samples = static_cast<size_t>(std::llround(cycleLength(design) / kArcStep));
  if (curvature.size() <= lap_samples) return;
  double lap_turn = 0.0;  // as integratePath sums it
  for (size_t i = 1; i <= lap_samples; ++i) lap_turn += 0.5 * (curvature[i - 1] + curvature[i]) * kArcStep;
  for (double& value : curvature) value *= 2.0 * M_PI / lap_turn;
}

std::vector<Pose2> integratePath(const std::vector<double>& curvature) {
  std::vector<Pose2> poses(curvature.size());
  for (size_t i = 1; i < curvature.size(); ++i) {
    const Pose2& previous = poses[i - 1];
    const double turn = 0.5 * (curvature[i - 1] + curvature[i]) * kArcStep;
    const double mid_heading = previous.heading + 0.5 * turn;
    poses[i] = {previous.x + kArcStep * std::cos(mid_heading), previous.y + kArcStep * std::sin(mid_heading),
                previous.heading + turn};
  }
  return poses;
}

// The fastest speed profile from rest under the cruise speed, the cornering limit, the stops, and
// the acceleration and braking limits (a forward then a backward pass).
std::vector<double> speedProfile(const std::vector<double>& curvature, double cruise_speed, double stop_spacing,
                                 const DrivingLimits& limits) {
  std::vector<double> speed(curvature.size());
  for (size_t i = 0; i < speed.size(); ++i) {
    const double cornering = std::abs(curvature[i]) > 0.0 ? std::sqrt(limits.lateral / std::abs(curvature[i]))
                                                          : cruise_speed;
    speed[i] = std::min(cruise_speed, cornering);
  }
  // Drives start standing, as recorded ones do (and as odometry expects of its first frames).
  speed[0] = 0.0;
  if (stop_spacing > 0.0) {
    const size_t stride = static_cast<size_t>(std::round(stop_spacing / kArcStep));
    for (size_t i = stride; i < speed.size(); i += stride) speed[i] = 0.0;
  }
  for (size_t i = 1; i < speed.size(); ++i) {
    speed[i] = std::min(speed[i], std::sqrt(speed[i - 1] * speed[i - 1] + 2.0 * limits.acceleration * kArcStep));
  }
  for (size_t i = speed.size() - 1; i-- > 0;) {
    speed[i] = std::min(speed[i], std::sqrt(speed[i + 1] * speed[i + 1] + 2.0 * limits.deceleration * kArcStep));
  }
  return speed;
}

std::vector<Hill> hillsAlong(const std::vector<Pose2>& path) {
  // Alternating hills and valleys centred on the road, steep enough (about 10 %) to pitch the vehicle.
  std::vector<Hill> hills;
  const double spacing = 400.0;
  for (double arc = 200.0; arc < path.size() * kArcStep; arc += spacing) {
    const Pose2& center = path[static_cast<size_t>(arc / kArcStep)];
    const bool valley = hills.size() % 2 == 1;
    hills.push_back(Hill{Eigen::Vector2d(center.x, center.y), 180.0, valley ? -8.0 : 12.0});
  }
  return hills;
}

double unwrapNear(double angle, double reference) {
  return reference + std::remainder(angle - reference, 2.0 * M_PI);
}

}  // namespace

double Hill::heightAt(const Eigen::Vector2d& point) const {
  const double distance = (point - center).norm();
  if (distance >= radius) return 0.0;
  return 0.5 * height * (1.0 + std::cos(M_PI * distance / radius));
}

Route::Route(std::vector<double> times, std::vector<Pose2> poses, std::vector<Hill> hills)
    : times_(std::move(times)), poses_(std::move(poses)), hills_(std::move(hills)) {
  if (times_.empty() || times_.size() != poses_.size()) {
    throw std::invalid_argument("a route needs as many times as poses, at least one");
  }
  for (size_t i = 1; i < poses_.size(); ++i) {
    if (times_[i] < times_[i - 1]) throw std::invalid_argument("route times must not decrease");
    poses_[i].heading = unwrapNear(poses_[i].heading, poses_[i - 1].heading);
  }
}

Pose2 Route::at(double time) const {
  if (time <= times_.front()) return poses_.front();
  if (time >= times_.back()) return poses_.back();
  const size_t upper = std::upper_bound(times_.begin(), times_.end(), time) - times_.begin();
  const size_t lower = upper - 1;
  const double span = times_[upper] - times_[lower];
  const double weight = span > 0.0 ? (time - times_[lower]) / span : 0.0;
  const Pose2& a = poses_[lower];
  const Pose2& b = poses_[upper];
  return {a.x + weight * (b.x - a.x), a.y + weight * (b.y - a.y), a.heading + weight * (b.heading - a.heading)};
}

std::vector<Eigen::Vector2d> Route::path(double spacing) const {
  std::vector<Eigen::Vector2d> points;
  for (const Pose2& pose : poses_) {
    const Eigen::Vector2d point(pose.x, pose.y);
    if (points.empty() || (point - points.back()).norm() >= spacing) points.push_back(point);
  }
  const Eigen::Vector2d last(poses_.back().x, poses_.back().y);
  if ((last - points.back()).norm() > 1e-6) points.push_back(last);
  return points;
}

namespace {
const std::map<std::string, TrajectoryKind>& trajectoryTable() {
  static const std::map<std::string, TrajectoryKind> table = {
      {"straight", TrajectoryKind::straight}, {"curves", TrajectoryKind::curves},
      {"roundabout", TrajectoryKind::roundabout}, {"hill", TrajectoryKind::hill},
      {"stop-and-go", TrajectoryKind::stop_and_go}, {"uturn", TrajectoryKind::uturn},
      {"loop", TrajectoryKind::loop}, {"hard-driving", TrajectoryKind::hard_driving}};
  return table;
}
}  // namespace

std::optional<TrajectoryKind> trajectoryKindFromName(const std::string& name) {
  const auto found = trajectoryTable().find(name);
  if (found == trajectoryTable().end()) return std::nullopt;
  return found->second;
}

std::string trajectoryName(TrajectoryKind kind) {
  for (const auto& [name, value] : trajectoryTable()) {
    if (value == kind) return name;
  }
  throw std::invalid_argument("unknown trajectory kind");
}

std::vector<std::string> trajectoryNames() {
  return {"straight", "curves", "roundabout", "hill", "stop-and-go", "uturn", "loop", "hard-driving"};
}

double loopLapDuration(double cruise_speed) {
  const double shortest_lap = 2.0 * M_PI * comfortableRadius(cruise_speed) + 2.0 * kLoopMinStraight;
  return std::ceil(shortest_lap / cruise_speed);
}

Route proceduralRoute(TrajectoryKind kind, double cruise_speed, double duration) {
  const RoadDesign design = designFor(kind, cruise_speed);
  // Never slower than cruise speed, so this much road always lasts the whole drive.
  const double length = cruise_speed * duration + 50.0;
  std::vector<double> curvature = curvatureProfile(design, length);
  if (design.closed_circuit) closeLaps(design, curvature);
  const std::vector<Pose2> path = integratePath(curvature);
  // The circuit's turns are at the comfortable radius for cruise speed: it is driven at cruise speed all
  // the way round, from the first frame on.
  const std::vector<double> speed = design.closed_circuit
                                        ? std::vector<double>(curvature.size(), cruise_speed)
                                        : speedProfile(curvature, cruise_speed, design.stop_spacing, design.limits);

  std::vector<double> times{0.0};
  std::vector<Pose2> poses{path[0]};
  for (size_t i = 1; i < path.size(); ++i) {
    times.push_back(times.back() + 2.0 * kArcStep / (speed[i - 1] + speed[i]));
    poses.push_back(path[i]);
    if (speed[i] == 0.0) {  // a stop: stand still, then drive on
      times.push_back(times.back() + kStopDuration);
      poses.push_back(path[i]);
    }
  }
  return Route(std::move(times), std::move(poses), design.hills ? hillsAlong(path) : std::vector<Hill>{});
}

Route routeFromPoses(const std::vector<Eigen::Isometry3d>& lidar_poses, double frame_period) {
  std::vector<double> times;
  std::vector<Pose2> poses;
  for (size_t i = 0; i < lidar_poses.size(); ++i) {
    const Eigen::Isometry3d& pose = lidar_poses[i];
    times.push_back(static_cast<double>(i) * frame_period);
    poses.push_back({pose.translation().x(), pose.translation().y(),
                     std::atan2(pose.linear()(1, 0), pose.linear()(0, 0))});
  }
  return Route(std::move(times), std::move(poses));
}

Eigen::Isometry3d kittiVeloToCam00() {
  Eigen::Matrix4d matrix;
  matrix << 4.276802385584e-04, -9.999672484946e-01, -8.084491683471e-03, -1.198459927713e-02,  //
      -7.210626507497e-03, 8.081198471645e-03, -9.999413164504e-01, -5.403984729748e-02,          //
      9.999738645903e-01, 4.859485810390e-04, -7.206933692422e-03, -2.921968648686e-01,           //
      0.0, 0.0, 0.0, 1.0;
  return Eigen::Isometry3d(matrix);
}

SensorTrajectory::SensorTrajectory(const Route& route, const GroundSurface& ground, double sensor_height,
                                   VehicleGeometry vehicle, Gait gait)
    : route_(route), ground_(ground), sensor_height_(sensor_height), vehicle_(vehicle), gait_(gait) {}

Eigen::Isometry3d SensorTrajectory::poseAt(double time) const {
  const Pose2 pose = route_.at(time);
  const Eigen::Vector2d position(pose.x, pose.y);
  const Eigen::Vector2d forward(std::cos(pose.heading), std::sin(pose.heading));
  const Eigen::Vector2d left(-forward.y(), forward.x());
  const auto onGround = [this](const Eigen::Vector2d& point) {
    return Eigen::Vector3d(point.x(), point.y(), ground_.height(point.x(), point.y()));
  };
  // The body lies in the plane of its wheels: pitch from the axles, roll from the wheel track.
  const Eigen::Vector3d along = onGround(position + 0.5 * vehicle_.wheelbase * forward) -
                                onGround(position - 0.5 * vehicle_.wheelbase * forward);
  const Eigen::Vector3d across = onGround(position + 0.5 * vehicle_.track * left) -
                                 onGround(position - 0.5 * vehicle_.track * left);
  Eigen::Matrix3d rotation;
  rotation.col(0) = along.normalized();
  rotation.col(2) = along.cross(across).normalized();
  rotation.col(1) = rotation.col(2).cross(rotation.col(0));

  Eigen::Isometry3d sensor = Eigen::Isometry3d::Identity();
  sensor.linear() = rotation;
  sensor.translation() = onGround(position) + Eigen::Vector3d(0.0, 0.0, sensor_height_);
  return sensor * gait_.offsetAt(time);
}

}  // namespace elo::sim
