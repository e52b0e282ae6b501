// The drive's map on analytic scans: one point per voxel at its points' centroid, placed by the scan's
// pose, the moving-object filter, bounded memory at a standstill, and the map's own thread.
#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <future>
#include <random>

#include "elo/map/drive_map.hpp"
#include "elo/map/map_builder.hpp"

namespace elo {
namespace {

MapScan scanOf(const std::vector<Vec3f>& points, bool ground = false, const Eigen::Isometry3d& pose = Eigen::Isometry3d::Identity()) {
  MapScan scan;
  scan.points = points;
  scan.normals.assign(points.size(), Vec3f::Zero());
  scan.intensity.assign(points.size(), 1.0f);
  scan.ground.assign(points.size(), ground ? 1 : 0);
  scan.pose = pose;
  return scan;
}

MapConfig everyVoxel() {
  MapConfig config;
  config.min_observations = 1;
  return config;
}

TEST(DriveMap, KeepsOnePointPerVoxelAtTheCentroidOfItsPoints) {
  DriveMap map(everyVoxel());  // 0.2 m voxels
  MapScan scan = scanOf({{1.01f, 2.01f, 0.05f}, {1.03f, 2.05f, 0.15f}, {1.31f, 2.01f, 0.05f}});
  scan.intensity = {10.0f, 20.0f, 7.0f};
  scan.normals = {Vec3f(0, 0, 1), Vec3f(0, 0, 1), Vec3f::Zero()};
  map.add(scan);
  const MapCloud cloud = map.points();
  ASSERT_EQ(cloud.size(), 2u);
  EXPECT_EQ(map.voxelCount(), 2u);
  for (size_t i = 0; i < cloud.size(); ++i) {
    if (cloud.points[i].x() < 1.2f) {
      EXPECT_LT((cloud.points[i] - Vec3f(1.02f, 2.03f, 0.10f)).norm(), 1e-5f);
      EXPECT_FLOAT_EQ(cloud.intensity[i], 15.0f);
      EXPECT_LT((cloud.normals[i] - Vec3f(0, 0, 1)).norm(), 1e-6f);
    } else {
      EXPECT_LT((cloud.points[i] - Vec3f(1.31f, 2.01f, 0.05f)).norm(), 1e-5f);
      EXPECT_TRUE(cloud.normals[i].isZero()) << "no normal known";
    }
  }
}

TEST(DriveMap, PlacesTheScanByItsPoseAndTurnsItsNormals) {
  DriveMap map(everyVoxel());
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.rotate(Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ()));
  pose.pretranslate(Eigen::Vector3d(1000.0, -500.0, 2.0));
  MapScan scan = scanOf({{10.05f, 0.05f, 0.05f}}, false, pose);
  scan.normals = {Vec3f(-1, 0, 0)};
  map.add(scan);
  const MapCloud cloud = map.points();
  ASSERT_EQ(cloud.size(), 1u);
  EXPECT_LT((cloud.points[0] - Vec3f(999.95f, -489.95f, 2.05f)).norm(), 1e-4f);
  EXPECT_LT((cloud.normals[0] - Vec3f(0, -1, 0)).norm(), 1e-6f);
}

TEST(DriveMap, LeavesOutNormalsThatDisagree) {
  DriveMap map(everyVoxel());
  MapScan scan = scanOf({{0.05f, 0.05f, 0.05f}, {0.06f, 0.05f, 0.05f}});
  scan.normals = {Vec3f(1, 0, 0), Vec3f(0, 1, 0)};
  map.add(scan);
  map.add(scanOf({{0.07f, 0.05f, 0.05f}}));
  scan.normals = {Vec3f(1, 0, 0), Vec3f(-1, 0, 0)};
  const MapCloud cloud = map.points();
  ASSERT_EQ(cloud.size(), 1u);
  EXPECT_LT((cloud.normals[0] - Vec3f(1, 1, 0).normalized()).norm(), 1e-6f) << "45 degrees apart: their mean";
  DriveMap opposite(everyVoxel());
  opposite.add(scan);
  EXPECT_TRUE(opposite.points().normals[0].isZero()) << "opposite normals cancel: none known";
}

TEST(DriveMap, WritesANonGroundVoxelOnlyOnceEnoughScansSawIt) {
  MapConfig config;
  config.min_observations = 3;
  DriveMap map(config);
  const MapScan object = scanOf({{5.05f, 0.05f, 1.05f}, {5.06f, 0.05f, 1.05f}});  // two points, one scan
  const MapScan road = scanOf({{3.05f, 0.05f, -1.7f}}, true);
  map.add(object);
  map.add(road);
  EXPECT_EQ(map.voxelCount(), 2u);
  ASSERT_EQ(map.points().size(), 1u) << "the road is written at once; the object, seen once, is not";
  EXPECT_LT(map.points().points[0].z(), 0.0f);
  map.add(object);
  EXPECT_EQ(map.points().size(), 1u);
  map.add(object);
  EXPECT_EQ(map.points().size(), 2u) << "seen by three scans";
}

// Standing still for 10 minutes (6,000 scans at 10 Hz) with 2 cm range noise: the map holds the voxels
// the noise reaches around each surface point, and no more as time goes by.
TEST(DriveMap, StandingStillKeepsMemoryBounded) {
  std::mt19937 rng(3);
  std::normal_distribution<float> noise(0.0f, 0.02f);
  std::vector<Vec3f> surface;
  for (int i = 0; i < 2000; ++i) surface.emplace_back(10.0f + 0.013f * i, -3.0f + 0.0037f * i, 0.5f);
  DriveMap map(everyVoxel());
  size_t voxels_after_a_minute = 0, bytes_after_a_minute = 0;
  for (int scan_number = 0; scan_number < 6000; ++scan_number) {
    std::vector<Vec3f> points = surface;
    for (Vec3f& point : points) point += point.normalized() * noise(rng);
    map.add(scanOf(points));
    if (scan_number == 599) {
      voxels_after_a_minute = map.voxelCount();
      bytes_after_a_minute = map.memoryBytes();
    }
  }
  std::cout << "voxels after 1 min " << voxels_after_a_minute << ", after 10 min " << map.voxelCount() << "; bytes "
            << bytes_after_a_minute << " -> " << map.memoryBytes() << std::endl;
  EXPECT_EQ(map.scanCount(), 6000u);
  // Only the noise's rare tails still reach a voxel now and then.
  EXPECT_LE(map.voxelCount(), voxels_after_a_minute + voxels_after_a_minute / 20);
  EXPECT_LE(map.memoryBytes(), bytes_after_a_minute + bytes_after_a_minute / 20);
}

TEST(DriveMap, CountsPointsBeyondItsExtent) {
  DriveMap map(everyVoxel());
  map.add(scanOf({{1.0f, 1.0f, 1.0f}, {5e6f, 0.0f, 0.0f}, {NAN, 0.0f, 0.0f}}));
  EXPECT_EQ(map.points().size(), 1u);
  EXPECT_EQ(map.pointsOutside(), 2u);
}

TEST(DriveMap, ThinsByStride) {
  DriveMap map(everyVoxel());
  std::vector<Vec3f> points;
  for (int i = 0; i < 100; ++i) points.emplace_back(0.1f + 0.2f * i, 0.1f, 0.1f);
  map.add(scanOf(points));
  EXPECT_EQ(map.points().size(), 100u);
  EXPECT_EQ(map.points(10).size(), 10u);
}

TEST(DriveMap, RejectsAnUnusableConfig) {
  MapConfig config;
  config.voxel_size = 0.0;
  EXPECT_THROW(DriveMap{config}, ConfigError);
  config = MapConfig{};
  config.min_observations = 0;
  EXPECT_THROW(DriveMap{config}, ConfigError);
  config = MapConfig{};
  config.scan_stride = 0;
  EXPECT_THROW(DriveMap{config}, ConfigError);
}

TEST(MapScanOf, CopiesTheOccupiedPixelsWithIntensityLabelAndNormalsFacingTheSensor) {
  ScanImage scan;
  scan.resize(2, 4);
  PointCloud cloud;
  cloud.points = {Vec3f(5, 0, 0), Vec3f(0, 5, -1.7f)};
  cloud.intensity = {40.0f, 3.0f};
  const auto put = [&](size_t pixel, int index, const Vec3f& normal, PixelLabel label) {
    scan.image.vertex[pixel] = cloud.points[index];
    scan.image.range[pixel] = cloud.points[index].norm();
    scan.image.normal[pixel] = normal;
    scan.point_index[pixel] = index;
    scan.label[pixel] = label;
  };
  put(1, 0, Vec3f(1, 0, 0), PixelLabel::nonground);  // facing away from the sensor: flipped
  put(6, 1, Vec3f::Zero(), PixelLabel::ground);
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.translation() = Eigen::Vector3d(1, 2, 3);
  const MapScan map_scan = mapScanOf(scan, cloud, pose, 12.5, 0.2);
  ASSERT_EQ(map_scan.points.size(), 2u);
  EXPECT_EQ(map_scan.points[0], cloud.points[0]);
  EXPECT_EQ(map_scan.normals[0], Vec3f(-1, 0, 0));
  EXPECT_EQ(map_scan.intensity[0], 40.0f);
  EXPECT_EQ(map_scan.ground[0], 0);
  EXPECT_EQ(map_scan.points[1], cloud.points[1]);
  EXPECT_TRUE(map_scan.normals[1].isZero());
  EXPECT_EQ(map_scan.intensity[1], 3.0f);
  EXPECT_EQ(map_scan.ground[1], 1);
  EXPECT_TRUE(map_scan.pose.isApprox(pose));
  EXPECT_EQ(map_scan.stamp, 12.5);
  cloud.intensity.clear();
  EXPECT_EQ(mapScanOf(scan, cloud, pose, 0.0, 0.2).intensity[0], 0.0f) << "no intensity: 0";
}

TEST(MapBuilder, BuildsTheSameMapOnItsThread) {
  MapBuilder builder(everyVoxel(), 32);
  DriveMap direct(everyVoxel());
  for (int i = 0; i < 20; ++i) {
    const MapScan scan = scanOf({{0.1f * i, 1.0f, 0.0f}, {0.1f * i, 2.0f, 0.0f}});
    direct.add(scan);
    EXPECT_TRUE(builder.add(scan));
  }
  EXPECT_EQ(builder.points().points.size(), direct.points().points.size());
  const MapBuilder::Statistics statistics = builder.statistics();
  EXPECT_EQ(statistics.scans, 20u);
  EXPECT_EQ(statistics.voxels, direct.voxelCount());
  EXPECT_EQ(statistics.dropped, 0u);
  builder.clear();
  EXPECT_EQ(builder.points().size(), 0u);
  EXPECT_EQ(builder.statistics().scans, 0u);
}

// Every scan_stride-th registered scan, the first included, and the count starts again after a clear:
// the first scan after the odometry restarted goes into the new map.
TEST(MapBuilder, TakesEveryStrideThScanCountingAgainAfterAClear) {
  MapConfig config = everyVoxel();
  config.scan_stride = 3;
  MapBuilder builder(config);
  std::vector<bool> taken;
  for (int i = 0; i < 7; ++i) taken.push_back(builder.takesNextScan());
  EXPECT_EQ(taken, (std::vector<bool>{true, false, false, true, false, false, true}));
  builder.clear();
  EXPECT_TRUE(builder.takesNextScan());
  EXPECT_FALSE(builder.takesNextScan());
  config.scan_stride = 1;
  MapBuilder every_scan(config);
  EXPECT_TRUE(every_scan.takesNextScan());
  EXPECT_TRUE(every_scan.takesNextScan());
}

TEST(MapBuilder, LeavesOutAndCountsAScanWhenItsQueueIsFull) {
  std::promise<void> release;
  std::shared_future<void> released = release.get_future().share();
  std::atomic<int> started{0};
  MapBuilder builder(everyVoxel(), 2, [&](const DriveMap&, const MapScan&) {
    ++started;
    released.wait();
  });
  EXPECT_TRUE(builder.add(scanOf({{1, 1, 1}})));
  while (started == 0) std::this_thread::yield();  // the first scan is being added: the queue is empty
  EXPECT_TRUE(builder.add(scanOf({{2, 1, 1}})));
  EXPECT_TRUE(builder.add(scanOf({{3, 1, 1}})));
  EXPECT_FALSE(builder.add(scanOf({{4, 1, 1}}))) << "a third scan waiting: the queue holds two";
  release.set_value();
  const MapBuilder::Statistics statistics = builder.statistics();
  EXPECT_EQ(statistics.scans, 3u);
  EXPECT_EQ(statistics.dropped, 1u);
}

}  // namespace
}  // namespace elo
