// Whole simulations: every world gives a plausible HDL-64E scan, every sensor fires its beams, the
// same seed gives byte-identical files, the written ground truth is the simulated motion at each scan's
// reference instant, and PCD scans keep their per-point times.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <iterator>

#include "../io/temp_directory.hpp"
#include "elo/io/kitti.hpp"
#include "elo/io/sequence.hpp"
#include "elo/sensor/sensor_model.hpp"
#include "elo/sim/sensors.hpp"
#include "elo/sim/sequence_writer.hpp"
#include "elo/sim/simulation.hpp"

namespace elo::sim {
namespace {

std::string fileBytes(const std::string& path) {
  std::ifstream file(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(file), std::istreambuf_iterator<char>());
}

size_t lineCount(const std::string& path) {
  std::ifstream file(path);
  size_t lines = 0;
  for (std::string line; std::getline(file, line);) ++lines;
  return lines;
}

double groundFraction(const SimulatedScan& scan) {
  size_t ground = 0;
  for (const SurfaceKind kind : scan.surface) ground += kind == SurfaceKind::ground ? 1 : 0;
  return static_cast<double>(ground) / static_cast<double>(scan.surface.size());
}

class EveryWorld : public ::testing::TestWithParam<std::string> {};

TEST_P(EveryWorld, GivesPlausibleHdl64Scans) {
  SimulationSpec spec;
  spec.world = *worldFamilyFromName(GetParam());
  spec.trajectory = TrajectoryKind::curves;
  spec.frames = 1000;
  const Simulation simulation(spec);
  // The ground's share over a drive: single scans vary with what stands beside the road (an open
  // field, a row of cars). On an open motorway the road alone fills the HDL-64E's lower block of
  // beams (-8.8 to -24.3 deg) and the next few above it, so most returns are ground there; elsewhere
  // facades, parked cars and vegetation take a third or more.
  const double most_ground = spec.world == WorldFamily::highway ? 0.92 : 0.7;
  // Indoors the ceiling and the walls 4 m away take the upper beams and most of the middle ones.
  const double least_ground = spec.world == WorldFamily::indoor ? 0.2 : 0.3;
  double ground_share = 0.0;
  int scans = 0;
  for (int frame = 0; frame < spec.frames; frame += 100, ++scans) {
    const SimulatedScan scan = simulation.scan(frame);
    EXPECT_GE(scan.cloud.size(), 60000u) << "frame " << frame;
    EXPECT_LE(scan.cloud.size(), 130000u) << "frame " << frame;
    ground_share += groundFraction(scan);
  }
  ground_share /= scans;
  EXPECT_GE(ground_share, least_ground);
  EXPECT_LE(ground_share, most_ground);
}

INSTANTIATE_TEST_SUITE_P(Worlds, EveryWorld, ::testing::ValuesIn(worldNames()),
                         [](const ::testing::TestParamInfo<std::string>& info) { return info.param; });

TEST(World, TheRoadStaysClearOfObjectsOnRoutesThatTurnBack) {
  for (const WorldFamily family : {WorldFamily::urban, WorldFamily::parking, WorldFamily::country}) {
    for (const TrajectoryKind kind : {TrajectoryKind::uturn, TrajectoryKind::roundabout}) {
      const Route route = proceduralRoute(kind, cruiseSpeed(family), 90.0);
      const World world(family, route, WorldOptions{});
      // Upward rays from just above the road along the path, and a car's width to either side.
      for (double time = 0.0; time < 90.0; time += 0.2) {
        const Pose2 pose = route.at(time);
        const Eigen::Vector2d left(-std::sin(pose.heading), std::cos(pose.heading));
        for (const double offset : {-1.0, 0.0, 1.0}) {
          const Eigen::Vector2d point = Eigen::Vector2d(pose.x, pose.y) + offset * left;
          const Ray up{Eigen::Vector3d(point.x(), point.y(), world.ground().height(point.x(), point.y()) + 0.05),
                       Eigen::Vector3d::UnitZ()};
          ASSERT_FALSE(world.scene().cast(up, 3.0))
              << worldName(family) << " " << trajectoryName(kind) << " blocked at t = " << time;
        }
      }
    }
  }
}

// The rails come in 4 m lots, each sharing its ends with the next: none may be taken for a revisit.
TEST(World, HighwayGuardRailsRunUnbrokenOnBothSides) {
  const double duration = 30.0;
  const Route route = proceduralRoute(TrajectoryKind::straight, cruiseSpeed(WorldFamily::highway), duration);
  const World world(WorldFamily::highway, route, WorldOptions{});
  int casts = 0;
  int rail_hits = 0;
  // Level rays across the road every metre, at the height of the rail's beam (0.42-0.74 m above the
  // verge, which lies 0.17 m below the middle lane there).
  const double step = 1.0 / cruiseSpeed(WorldFamily::highway);
  for (double time = 1.0; time < duration - 1.0; time += step) {
    const Pose2 pose = route.at(time);
    const Eigen::Vector2d left(-std::sin(pose.heading), std::cos(pose.heading));
    const double height = world.ground().height(pose.x, pose.y) + 0.45;
    for (const double side : {1.0, -1.0}) {
      const Ray across{Eigen::Vector3d(pose.x, pose.y, height),
                       Eigen::Vector3d(side * left.x(), side * left.y(), 0.0)};
      const std::optional<Hit> hit = world.scene().cast(across, 12.0);
      ++casts;
      rail_hits += hit && std::abs(hit->distance - 9.5) < 0.2 ? 1 : 0;
    }
  }
  EXPECT_EQ(rail_hits, casts);
}

// Every configured sensor fires the beams of its configuration (config/NAME.yaml), numbered as its driver
// numbers them, here all in one street canyon.
TEST(Sensors, EachFiresItsBeams) {
  SimulationSpec street;
  street.frames = 2;
  const Simulation simulation(street);
  const Eigen::Isometry3d pose = simulation.sensorPose(1);
  // Without the car, whose roof hides a dome's lower beams all round, and with firings a degree apart:
  // the beams are what this checks.
  LidarOptions options;
  options.vehicle_body.clear();
  for (const std::string& name : sensorNames()) {
    Config config;
    loadSensor(name, config);
    config.sensor.azimuth_steps = 360;
    const Lidar lidar(config.sensor, options);
    const int beams = config.sensor.beam_count;
    EXPECT_EQ(lidar.beamCount(), beams) << name;
    const SimulatedScan scan = lidar.sweep(simulation.world().scene(), [&](double) { return pose; }, 0.0, 1);
    std::vector<bool> seen(beams, false);
    for (const uint16_t ring : scan.cloud.ring) seen[ring] = true;
    // In a street canyon every beam, up or down, meets the road or a facade somewhere.
    EXPECT_EQ(std::count(seen.begin(), seen.end(), true), beams) << name;
    const std::vector<float> rings = ringElevations(config.sensor);
    for (size_t i = 0; i < scan.cloud.size(); ++i) {
      const Vec3f& point = scan.cloud.points[i];
      ASSERT_LE(point.norm(), config.sensor.max_range + 1e-3) << name;
      // The ring names the beam that fired the point (range noise keeps its direction).
      const float elevation = std::atan2(point.z(), point.head<2>().norm());
      ASSERT_NEAR(elevation, rings[scan.cloud.ring[i]], 0.01 * M_PI / 180.0) << name << ", ring " << scan.cloud.ring[i];
    }
  }
  Config config;
  EXPECT_THROW(loadSensor("hdl128", config), std::invalid_argument);
}

SimulationSpec smallSpec(uint64_t seed) {
  SimulationSpec spec;
  loadSensor("vlp16", spec.config);
  spec.world = WorldFamily::urban;
  spec.trajectory = TrajectoryKind::straight;
  spec.frames = 12;
  spec.seed = seed;
  spec.moving_cars = 6;
  return spec;
}

TEST(Sequence, SameSeedSameBytesOtherSeedOtherScans) {
  const elo::test::TempDirectory directory;
  const auto write = [&](uint64_t seed, const std::string& name) {
    const Simulation simulation(smallSpec(seed));
    writeSequence(simulation, directory.file(name));
  };
  write(5, "a");
  write(5, "b");
  write(6, "c");
  for (const std::string scan : {"000000.bin", "000011.bin"}) {
    const std::string a = fileBytes(directory.file("a/velodyne/" + scan));
    ASSERT_FALSE(a.empty());
    EXPECT_EQ(a, fileBytes(directory.file("b/velodyne/" + scan))) << scan;
    EXPECT_NE(a, fileBytes(directory.file("c/velodyne/" + scan))) << scan;
  }
  EXPECT_EQ(fileBytes(directory.file("a/poses.txt")), fileBytes(directory.file("b/poses.txt")));
}

TEST(Sequence, GroundTruthIsTheSimulatedMotion) {
  const elo::test::TempDirectory directory;
  SimulationSpec spec = smallSpec(1);
  spec.frames = 30;
  const Simulation simulation(spec);
  const SequenceSummary summary = writeSequence(simulation, directory.file("seq"));
  EXPECT_EQ(summary.frames, 30);

  const std::vector<Eigen::Isometry3d> poses = readKittiPoses(directory.file("seq/poses.txt"));
  ASSERT_EQ(poses.size(), 30u);
  EXPECT_TRUE(poses[0].isApprox(Eigen::Isometry3d::Identity(), 0.0));
  const Route& route = simulation.trajectory().route();
  for (size_t i = 1; i < poses.size(); ++i) {
    const Eigen::Isometry3d step = poses[i - 1].inverse() * poses[i];
    // A straight drive accelerating from rest: each frame moves as far as the route's speed profile
    // says (over a gentle terrain, so the 3D step is the 2D one to 1 %), and forward.
    const Pose2 from = route.at(simulation.stamp(static_cast<int>(i) - 1));
    const Pose2 to = route.at(simulation.stamp(static_cast<int>(i)));
    const double planned = std::hypot(to.x - from.x, to.y - from.y);
    EXPECT_NEAR(step.translation().norm(), planned, 0.01 * planned + 1e-6) << "frame " << i;
    EXPECT_GT(step.translation().x(), 0.99 * step.translation().norm());
    // And it is the pose the scan was taken from, relative to the first.
    const Eigen::Isometry3d simulated = simulation.sensorPose(0).inverse() * simulation.sensorPose(static_cast<int>(i));
    EXPECT_TRUE(simulated.isApprox(poses[i], 1e-9));
  }
  // At 1.5 m/s^2 from rest, the step from 2.8 s to 2.9 s covers 0.1 s at the mean speed 4.275 m/s.
  const double last_step = (poses[28].inverse() * poses[29]).translation().norm();
  EXPECT_NEAR(last_step, 0.1 * 1.5 * 2.85, 0.01);

  const std::vector<double> stamps = readTimes(directory.file("seq/times.txt"));
  ASSERT_EQ(stamps.size(), 30u);
  EXPECT_DOUBLE_EQ(stamps[0], 0.0);
  EXPECT_NEAR(stamps[29], 2.9, 1e-9);
  EXPECT_TRUE(readKittiCalibration(directory.file("seq/calib.txt")).isApprox(kittiVeloToCam00(), 1e-12));
  const PointCloud first = readKittiBin(directory.file("seq/velodyne/000000.bin"));
  EXPECT_EQ(first.size(), simulation.scan(0).cloud.size());
  EXPECT_EQ(lineCount(directory.file("seq/poses.txt")), 30u);
}

// A sweep with motion in the azimuth convention (KITTI's .bin) is referred to mid-sweep: its stamp
// (times.txt) and its ground truth lie half a sweep after the sweep's start.
TEST(Sequence, AzimuthConventionRefersStampsAndGroundTruthToMidSweep) {
  const elo::test::TempDirectory directory;
  SimulationSpec spec = smallSpec(1);
  spec.lidar.deskewed = false;
  spec.lidar.time_convention = TimeConvention::azimuth;
  const Simulation simulation(spec);
  writeSequence(simulation, directory.file("seq"));
  const std::vector<double> stamps = readTimes(directory.file("seq/times.txt"));
  const std::vector<Eigen::Isometry3d> poses = readKittiPoses(directory.file("seq/poses.txt"));
  ASSERT_EQ(stamps.size(), 12u);
  ASSERT_EQ(poses.size(), 12u);
  const SensorTrajectory& trajectory = simulation.trajectory();
  for (int frame = 0; frame < 12; ++frame) {
    EXPECT_NEAR(stamps[frame], 0.1 * frame + 0.05, 1e-9);
    EXPECT_DOUBLE_EQ(simulation.scan(frame).cloud.stamp, simulation.sweepStart(frame) + 0.05);
    const Eigen::Isometry3d mid_sweep = trajectory.poseAt(0.05).inverse() * trajectory.poseAt(0.1 * frame + 0.05);
    EXPECT_TRUE(poses[frame].isApprox(mid_sweep, 1e-9)) << "frame " << frame;
  }
  // Not a standing car, for which every reference instant gives the same pose: 0.9 m in 1.1 s from rest.
  EXPECT_GT(poses[11].translation().norm(), 0.5);
}

// PCD scans keep what a .bin cannot: the ring, and the field convention's per-point times.
TEST(Sequence, PcdScansCarryTheFieldTimes) {
  const elo::test::TempDirectory directory;
  SimulationSpec spec = smallSpec(1);
  spec.frames = 3;
  spec.lidar.deskewed = false;
  spec.lidar.time_convention = TimeConvention::field;
  const Simulation simulation(spec);
  writeSequence(simulation, directory.file("seq"), ScanFormat::pcd);
  const Sequence sequence(directory.file("seq"));
  ASSERT_EQ(sequence.size(), 3u);
  ASSERT_TRUE(sequence.hasGroundTruth());
  for (size_t frame = 0; frame < 3; ++frame) {
    const PointCloud expected = simulation.scan(static_cast<int>(frame)).cloud;
    const PointCloud read = sequence.load(frame);
    ASSERT_EQ(read.size(), expected.size());
    EXPECT_EQ(read.time, expected.time);
    EXPECT_EQ(read.ring, expected.ring);
    EXPECT_NEAR(read.stamp, simulation.stamp(static_cast<int>(frame)), 1e-9);
  }
}

TEST(Traffic, MovingCarsAppearAndMove) {
  SimulationSpec spec;
  spec.world = WorldFamily::highway;
  spec.trajectory = TrajectoryKind::straight;
  spec.frames = 200;
  spec.moving_cars = 40;
  const Simulation simulation(spec);
  size_t moving_points = 0;
  for (int frame = 0; frame < spec.frames; frame += 40) {
    const SimulatedScan scan = simulation.scan(frame);
    for (const SurfaceKind kind : scan.surface) moving_points += kind == SurfaceKind::moving_object ? 1 : 0;
  }
  EXPECT_GT(moving_points, 100u);
}

}  // namespace
}  // namespace elo::sim
