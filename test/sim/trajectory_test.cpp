// Routes, the vehicle standing on the simulated ground, and drives through KITTI poses.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <iostream>

#include "../io/temp_directory.hpp"
#include "elo/eval/uniform_instants.hpp"
#include "elo/io/kitti.hpp"
#include "elo/sim/simulation.hpp"
#include "elo/sim/trajectory.hpp"

namespace elo::sim {
namespace {

double speedAt(const Route& route, double time) {
  const double step = 0.05;
  const Pose2 a = route.at(time);
  const Pose2 b = route.at(time + step);
  return std::hypot(b.x - a.x, b.y - a.y) / step;
}

TEST(Route, ProceduralDrivesKeepRealisticSpeeds) {
  for (const std::string& name : trajectoryNames()) {
    const TrajectoryKind kind = *trajectoryKindFromName(name);
    const Route route = proceduralRoute(kind, 12.0, 120.0);
    if (kind != TrajectoryKind::loop) {
      EXPECT_LT(speedAt(route, 0.0), 0.5) << name << " does not start from rest";
    }
    // Once up to speed (1.5 m/s^2 takes 8 s to 12 m/s), never crawling except at stops.
    double slowest = 1e9, fastest = 0.0, distance = 0.0;
    for (double t = 0.0; t < 120.0; t += 0.05) {
      const double speed = speedAt(route, t);
      if (t > 10.0) slowest = std::min(slowest, speed);
      fastest = std::max(fastest, speed);
      distance += speed * 0.05;
    }
    EXPECT_LE(fastest, 12.0 + 1e-6) << name;
    const bool stops = kind == TrajectoryKind::stop_and_go || kind == TrajectoryKind::hard_driving;
    // The hard-driven car takes its town corners at 6-8 m/s and stops every 100 m.
    EXPECT_GT(distance / 120.0, kind == TrajectoryKind::hard_driving ? 4.0 : stops ? 6.0 : 7.0) << name;
    if (stops) {
      EXPECT_LT(slowest, 1e-9) << name << " never stops";
    } else {
      EXPECT_GT(slowest, 3.0) << name;
    }
    EXPECT_EQ(trajectoryName(kind), name);
  }
  EXPECT_FALSE(trajectoryKindFromName("spiral"));
}


// Braking at 0.8 g, corners at 5 m/s^2 and a turn rate a car never reaches on the comfortable drives, at a
// town's speeds: the speed over 0.5 s windows, the turn rate over 0.1 s.
TEST(Route, TheHardDrivenCarBrakesAtPointEightGAndTurnsFastAtLowSpeed) {
  const Route route = proceduralRoute(TrajectoryKind::hard_driving, 10.0, 60.0);
  const double window = 0.5;
  double hardest_braking = 0.0, hardest_cornering = 0.0, fastest_turn = 0.0, speed_at_fastest_turn = 0.0;
  for (double t = 0.0; t + 2.0 * window < 60.0; t += 0.05) {
    const double before = speedAt(route, t);
    const double after = speedAt(route, t + window);
    hardest_braking = std::max(hardest_braking, (before - after) / window);
    const double turn_rate = std::abs(route.at(t + 0.1).heading - route.at(t).heading) / 0.1;
    hardest_cornering = std::max(hardest_cornering, turn_rate * before);
    if (turn_rate > fastest_turn) {
      fastest_turn = turn_rate;
      speed_at_fastest_turn = before;
    }
  }
  EXPECT_NEAR(hardest_braking, 0.8 * 9.81, 0.5);
  EXPECT_LT(hardest_cornering, 5.5);
  EXPECT_GT(hardest_cornering, 4.0);
  EXPECT_GT(fastest_turn * 180.0 / M_PI, 35.0);
  EXPECT_LT(speed_at_fastest_turn, 8.0);
}
TEST(Route, TurnsOfEachDesign) {
  // A U-turn reverses the heading; a roundabout turns left by 90 deg net.
  const Route uturn = proceduralRoute(TrajectoryKind::uturn, 10.0, 60.0);
  const Route roundabout = proceduralRoute(TrajectoryKind::roundabout, 10.0, 60.0);
  const auto headingAfter = [](const Route& route, double metres) {
    double travelled = 0.0, time = 0.0;
    while (travelled < metres) {
      travelled += speedAt(route, time) * 0.05;
      time += 0.05;
    }
    return route.at(time).heading;
  };
  EXPECT_NEAR(headingAfter(uturn, 215.0), M_PI, 0.02);
  EXPECT_NEAR(headingAfter(roundabout, 175.0), M_PI / 2.0, 0.02);
}

// The soak test replays one lap of the loop end to end: the frame after the lap must be the first
// frame again, in pose and in velocity, or every replayed lap would start with a jump.
TEST(Route, LoopLapsRetraceTheFirstInPlaceAndTime) {
  SimulationSpec spec;
  spec.world = WorldFamily::urban;
  spec.trajectory = TrajectoryKind::loop;
  const double lap_seconds = loopLapDuration(cruiseSpeed(spec.world));
  EXPECT_EQ(lap_seconds, 40.0) << "urban: 10 m/s on a 400 m circuit (the README and tools/soak.sh say 400 frames)";
  const int lap_frames = static_cast<int>(lap_seconds * spec.config.sensor.rotation_rate_hz);
  spec.frames = 2 * lap_frames;
  const Simulation simulation(spec);
  double largest_translation = 0.0, largest_rotation = 0.0;
  for (int frame = 0; frame < lap_frames; frame += 7) {
    const Eigen::Isometry3d difference = simulation.sensorPose(frame).inverse() * simulation.sensorPose(frame + lap_frames);
    largest_translation = std::max(largest_translation, difference.translation().norm());
    largest_rotation = std::max(largest_rotation, Eigen::AngleAxisd(difference.linear()).angle());
  }
  EXPECT_LT(largest_translation, 1e-3);
  EXPECT_LT(largest_rotation, 1e-5);
  // At cruise speed all the way round, the seam included.
  const Route& route = simulation.trajectory().route();
  for (double t = 0.0; t < lap_seconds; t += 0.5) EXPECT_NEAR(speedAt(route, t), 10.0, 1e-3) << "at " << t << " s";
  const Eigen::Vector3d first_step = simulation.sensorPose(1).translation() - simulation.sensorPose(0).translation();
  EXPECT_NEAR(first_step.norm(), 1.0, 1e-3);
}

TEST(SensorTrajectory, SensorStandsAtItsHeightOnSlopesAndTiltsWithThem) {
  SimulationSpec spec;
  spec.world = WorldFamily::country;
  spec.trajectory = TrajectoryKind::hill;
  spec.frames = 400;
  const Simulation simulation(spec);
  double steepest_pitch = 0.0;
  for (int frame = 0; frame < spec.frames; frame += 7) {
    const Eigen::Isometry3d pose = simulation.sensorPose(frame);
    const Eigen::Vector3d p = pose.translation();
    EXPECT_NEAR(p.z() - simulation.world().ground().height(p.x(), p.y()), spec.config.ground.sensor_height, 1e-9);
    steepest_pitch = std::max(steepest_pitch, std::abs(std::asin(pose.linear()(2, 0))));
    // The body's up axis is the ground's normal to within the wheelbase's averaging.
    const Eigen::Vector3d normal = simulation.world().ground().normal(p.x(), p.y());
    EXPECT_GT(pose.linear().col(2).dot(normal), std::cos(3.0 * M_PI / 180.0));
  }
  EXPECT_GT(steepest_pitch, 3.0 * M_PI / 180.0) << "the hill drive never climbs";
}

std::vector<Eigen::Isometry3d> curvyLidarPoses(int count) {
  std::vector<Eigen::Isometry3d> poses;
  for (int i = 0; i < count; ++i) {
    const double t = 0.1 * i;
    Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
    const double heading = 0.3 * std::sin(0.2 * t);
    pose.linear() = Eigen::AngleAxisd(heading, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    pose.translation() = Eigen::Vector3d(9.0 * t, 20.0 * (1.0 - std::cos(0.2 * t)), 0.3 * t);
    poses.push_back(pose);
  }
  // Relative to the first, as KITTI's are.
  const Eigen::Isometry3d first_inverse = poses.front().inverse();
  for (Eigen::Isometry3d& pose : poses) pose = first_inverse * pose;
  return poses;
}

// The hand-held walk's gait: the yaw swing peaks at 2 pi f A = 188 deg/s, the rocking and the bob stay
// within their amplitudes, and the offset is the identity at time 0; a trot's jolts lower the sensor at
// each footfall.
TEST(Gait, WalkAndTrotMoveTheSensorAsDescribed) {
  const Gait walk = handheldWalk();
  EXPECT_TRUE(walk.offsetAt(0.0).isApprox(Eigen::Isometry3d::Identity(), 1e-12));
  double fastest_yaw_rate = 0.0;
  for (double t = 0.0; t < 2.0; t += 0.001) {
    const Eigen::Isometry3d a = walk.offsetAt(t);
    const Eigen::Isometry3d b = walk.offsetAt(t + 0.001);
    const auto yaw = [](const Eigen::Isometry3d& pose) { return std::atan2(pose.linear()(1, 0), pose.linear()(0, 0)); };
    fastest_yaw_rate = std::max(fastest_yaw_rate, std::abs(yaw(b) - yaw(a)) / 0.001);
    EXPECT_LE(std::abs(a.translation().z()), walk.bob_m + 1e-12);
    const Eigen::Vector3d up = a.rotation() * Eigen::Vector3d::UnitZ();
    EXPECT_LE(std::acos(up.z()) * 180.0 / M_PI, walk.sway_deg * 1.2);
  }
  EXPECT_NEAR(fastest_yaw_rate * 180.0 / M_PI, 188.5, 5.0);
  const Gait robot = trot();
  EXPECT_NEAR(robot.offsetAt(0.0).translation().z(), -robot.bob_m, 1e-12) << "a footfall at time 0";
  EXPECT_NEAR(robot.offsetAt(0.5 / robot.step_hz).translation().z(), 0.0, 1e-3) << "between footfalls";
  EXPECT_FALSE(gaitFromName("hop"));
  EXPECT_TRUE(gaitFromName("walk"));
}

// The recorded ground truth taken SimulationSpec::truth_time_offset after each stamp, as KITTI-raw's OXTS
// poses are off its scans' (docs/real_drives.md): the sensor's pose at the shifted instant, the scans and
// sensorPose() as they were; over a turn the truth's rotation between two scans is off the exact one's by
// the turn over the offset at each end.
TEST(Simulation, TheRecordedTruthIsTakenTheTruthTimeOffsetAfterEachStamp) {
  SimulationSpec spec;
  spec.trajectory = TrajectoryKind::curves;
  spec.frames = 400;
  SimulationSpec offset_spec = spec;
  offset_spec.truth_time_offset = -0.012;
  const Simulation exact(spec);
  const Simulation offset(offset_spec);
  double largest_rotation_error = 0.0;
  double largest_bound = 0.0;
  for (int frame = 0; frame < spec.frames; ++frame) {
    ASSERT_TRUE(exact.recordedTruth(frame).isApprox(exact.sensorPose(frame), 0.0)) << frame;
    ASSERT_TRUE(offset.sensorPose(frame).isApprox(exact.sensorPose(frame), 0.0)) << frame;
    ASSERT_TRUE(offset.recordedTruth(frame).isApprox(offset.trajectory().poseAt(offset.stamp(frame) - 0.012), 0.0)) << frame;
    if (frame == 0) continue;
    const Eigen::Matrix3d truth_step = exact.sensorPose(frame - 1).linear().transpose() * exact.sensorPose(frame).linear();
    const Eigen::Matrix3d recorded_step =
        offset.recordedTruth(frame - 1).linear().transpose() * offset.recordedTruth(frame).linear();
    largest_rotation_error = std::max(largest_rotation_error, Eigen::AngleAxisd(truth_step.transpose() * recorded_step).angle());
    // The turn over the offset at either end of the step.
    const auto turn_over_offset = [&](int at) {
      return Eigen::AngleAxisd(offset.recordedTruth(at).linear().transpose() * exact.sensorPose(at).linear()).angle();
    };
    largest_bound = std::max(largest_bound, turn_over_offset(frame - 1) + turn_over_offset(frame));
  }
  EXPECT_GT(largest_rotation_error, 1e-5) << "the curves turn: the offset shows";
  EXPECT_LE(largest_rotation_error, largest_bound + 1e-12);
}

// KITTI-raw's ground truth, taken at stamps rounded to 10 ms from a sensor turning at 9.66 Hz
// (SimulationSpec::truth_at_recorded_stamps): the sensor's pose at each recorded stamp, up to 5 ms of
// travel off the scan's; the line fitted to the stamps and the truth interpolated to it (elo_eval
// --gt-times) give back the poses at the scans' instants.
TEST(Simulation, TheTruthAtTheRoundedStampsIsMovedBackToTheScansInstantsByTheFittedLine) {
  SimulationSpec spec;
  spec.trajectory = TrajectoryKind::curves;
  spec.frames = 300;
  spec.config.sensor.rotation_rate_hz = 9.66;
  spec.stamp_rounding = 0.01;
  spec.truth_at_recorded_stamps = true;
  const Simulation simulation(spec);
  std::vector<double> stamps;
  std::vector<Eigen::Isometry3d> recorded;
  double largest_offset = 0.0;
  for (int frame = 0; frame < spec.frames; ++frame) {
    stamps.push_back(simulation.recordedStamp(frame));
    recorded.push_back(simulation.recordedTruth(frame));
    ASSERT_TRUE(recorded.back().isApprox(simulation.trajectory().poseAt(stamps.back()), 0.0)) << frame;
    largest_offset = std::max(largest_offset,
                              (recorded.back().translation() - simulation.sensorPose(frame).translation()).norm());
  }
  EXPECT_GT(largest_offset, 0.03) << "the stamps are rounded by up to 5 ms";
  const std::vector<Eigen::Isometry3d> moved = interpolatePoses(recorded, stamps, fitUniformInstants(stamps).instants);
  double largest_error = 0.0;
  for (int frame = 0; frame < spec.frames; ++frame) {
    largest_error = std::max(largest_error, (moved[frame].translation() - simulation.sensorPose(frame).translation()).norm());
  }
  std::cout << "truth at the rounded stamps up to " << largest_offset << " m off the scans', moved back to "
            << largest_error << " m" << std::endl;
  EXPECT_LT(largest_error, 0.005);
}

TEST(SensorTrajectory, DrivenPosesAreFollowedInXY) {
  // Through a camera-frame KITTI file, as --poses reads one.
  const elo::test::TempDirectory directory;
  const std::vector<Eigen::Isometry3d> lidar = curvyLidarPoses(60);
  writeKittiPoses(directory.file("poses.txt"), lidarToCamera(lidar, kittiVeloToCam00()));
  SimulationSpec spec;
  spec.driven_poses = cameraToLidar(readKittiPoses(directory.file("poses.txt")), kittiVeloToCam00());
  spec.frames = 60;
  const Simulation simulation(spec);
  for (int frame = 0; frame < spec.frames; ++frame) {
    const Eigen::Isometry3d simulated = simulation.sensorPose(frame);
    EXPECT_NEAR(simulated.translation().x(), lidar[frame].translation().x(), 1e-6);
    EXPECT_NEAR(simulated.translation().y(), lidar[frame].translation().y(), 1e-6);
    const Eigen::Vector3d forward = simulated.linear().col(0);
    const Eigen::Vector3d expected = lidar[frame].linear().col(0);
    EXPECT_NEAR(std::atan2(forward.y(), forward.x()), std::atan2(expected.y(), expected.x()), 1e-6);
  }
  spec.frames = 61;
  EXPECT_THROW(Simulation{spec}, std::invalid_argument);
}

TEST(SensorTrajectory, KittiSequence00IsFollowedInXY) {
  const std::string path = std::string(ELO_SHARED_DATA) + "/kitti_gt/poses/00.txt";
  if (!std::filesystem::exists(path)) GTEST_SKIP() << "no KITTI ground truth at " << path;
  const std::vector<Eigen::Isometry3d> lidar = cameraToLidar(readKittiPoses(path), kittiVeloToCam00());
  SimulationSpec spec;
  spec.driven_poses = lidar;
  spec.frames = 300;
  const Simulation simulation(spec);
  for (int frame = 0; frame < spec.frames; frame += 10) {
    const Eigen::Vector3d simulated = simulation.sensorPose(frame).translation();
    EXPECT_NEAR(simulated.x(), lidar[frame].translation().x(), 1e-6);
    EXPECT_NEAR(simulated.y(), lidar[frame].translation().y(), 1e-6);
  }
}

}  // namespace
}  // namespace elo::sim
