// The saved map of localization: loading and cleaning it, its normals, its tile index, and rendering it
// into a backend's map model, and the part of it a GPU holds, on analytic maps with exact answers.
#include <gtest/gtest.h>

#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <numeric>
#include <random>

#include "elo/pipeline/backend.hpp"
#include "elo/io/io_error.hpp"
#include "elo/io/map_pcd.hpp"
#include "core/map/map_residency.hpp"
#include "elo/map/point_map.hpp"

namespace elo {
namespace {

// A square of the plane z = height, `size` metres wide, one point every `step` metres.
void addFloor(MapCloud& map, double size, double step, double height) {
  for (double x = -size / 2; x < size / 2; x += step) {
    for (double y = -size / 2; y < size / 2; y += step) map.points.emplace_back(x, y, height);
  }
}

// A wall x = distance, from y -width/2 to width/2 and z 0 to height.
void addWall(MapCloud& map, double distance, double width, double height, double step) {
  for (double y = -width / 2; y < width / 2; y += step) {
    for (double z = step / 2; z < height; z += step) map.points.emplace_back(distance, y, z);
  }
}

TEST(MapCloud, PreparationDropsNonFinitePointsAndFitsPlaneNormals) {
  MapCloud map;
  addFloor(map, 4.0, 0.1, 0.5);
  const size_t floor_points = map.size();
  map.points.emplace_back(NAN, 0.0f, 0.0f);
  map.points.emplace_back(0.0f, INFINITY, 0.0f);
  const MapPreparation preparation = prepareMap(map, 0.5);
  EXPECT_EQ(preparation.non_finite_dropped, 2u);
  EXPECT_TRUE(preparation.estimated);
  ASSERT_EQ(map.size(), floor_points);
  ASSERT_TRUE(map.hasNormals());
  EXPECT_EQ(preparation.normals_estimated, floor_points);
  for (const Vec3f& normal : map.normals) EXPECT_NEAR(std::abs(normal.z()), 1.0f, 1e-5f);
}

TEST(MapCloud, IsolatedPointsGetNoNormalAndBadNormalsAreDropped) {
  MapCloud lonely;
  lonely.points = {{0, 0, 0}, {5, 0, 0}, {10, 0, 0}};
  prepareMap(lonely, 0.5);
  for (const Vec3f& normal : lonely.normals) EXPECT_TRUE(normal.isZero());

  MapCloud given;
  given.points = {{0, 0, 0}, {1, 0, 0}, {2, 0, 0}};
  given.normals = {{0, 0, 1}, {0, 0, 2}, {NAN, 0, 0}};
  const MapPreparation preparation = prepareMap(given, 0.5);
  EXPECT_FALSE(preparation.estimated);
  EXPECT_EQ(preparation.bad_normals, 2u);
  EXPECT_EQ(given.normals[0], Vec3f(0, 0, 1));
  EXPECT_TRUE(given.normals[1].isZero());
  EXPECT_TRUE(given.normals[2].isZero());
}

TEST(MapCloud, TilesFindExactlyThePointsWithinTheRadius) {
  MapCloud map;
  std::mt19937 random(3);
  std::uniform_real_distribution<float> coordinate(-300.0f, 300.0f);
  for (int i = 0; i < 20000; ++i) map.points.emplace_back(coordinate(random), coordinate(random), coordinate(random) / 50);
  for (const double tile : {7.0, 20.0, 100.0}) {
    const MapTiles tiles(map, tile);
    for (const Eigen::Vector3d& center : {Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(-250, 130, 4), Eigen::Vector3d(290, 299, 0)}) {
      std::vector<int32_t> found;
      tiles.pointsNear(center, 60.0, found);
      std::sort(found.begin(), found.end());
      std::vector<int32_t> expected;
      for (size_t i = 0; i < map.size(); ++i) {
        if ((map.points[i].head<2>().cast<double>() - center.head<2>()).norm() <= 60.0) expected.push_back(static_cast<int32_t>(i));
      }
      EXPECT_EQ(found, expected) << "tile " << tile << " centre " << center.transpose();
    }
  }
}

// The CUDA backend's share of the map (MapResidency) down a 1 km road, rendered every 2 m within 60 m:
// every render finds its points held and where it was told, a new set is chosen once every two tiles
// travelled (the ring around the drawn tiles is what spares the tile in between), and the device holds
// only the tiles within the render's reach and one more: a fifth of the map, not all of it.
TEST(MapResidency, HoldsOnlyTheTilesNearTheRendersAndFindsEveryPointDrawn) {
  MapCloud map;
  std::mt19937 random(5);
  std::uniform_real_distribution<float> along(-500.0f, 500.0f);
  std::uniform_real_distribution<float> across(-20.0f, 20.0f);
  for (int i = 0; i < 20000; ++i) map.points.emplace_back(along(random), across(random), 0.0f);
  constexpr double kTile = 20.0;
  constexpr double kReach = 60.0;
  const MapTiles tiles(map, kTile);
  MapResidency residency(map, kTile);
  int choices = 0;
  size_t most_held = 0;
  for (double x = -490.0; x <= 490.0; x += 2.0) {
    std::vector<int32_t> drawn;
    tiles.pointsNear(Eigen::Vector3d(x, 0.0, 0.0), kReach, drawn);
    std::vector<int32_t> places(drawn.size());
    if (!residency.locate(drawn, places.data())) {
      residency.holdAround(drawn);
      ++choices;
      for (const int32_t point : residency.held()) {
        ASSERT_LE(std::abs(map.points[point].x() - x), kReach + 2 * kTile) << "a tile beyond the ring, at x " << x;
      }
      most_held = std::max(most_held, residency.held().size());
      ASSERT_TRUE(residency.locate(drawn, places.data())) << "at x " << x;
    }
    for (size_t i = 0; i < drawn.size(); ++i) ASSERT_EQ(residency.held()[places[i]], drawn[i]) << "at x " << x;
  }
  std::printf("%d sets held over 980 m; at most %zu of the map's %zu points\n", choices, most_held, map.size());
  EXPECT_LE(choices, 1 + 980 / 40);
  EXPECT_LE(most_held, map.size() / 4);
  EXPECT_GT(most_held, map.size() / 10);

  residency.release();
  EXPECT_TRUE(residency.held().empty());
  std::vector<int32_t> drawn;
  tiles.pointsNear(Eigen::Vector3d(0.0, 0.0, 0.0), kReach, drawn);
  std::vector<int32_t> places(drawn.size());
  EXPECT_FALSE(residency.locate(drawn, places.data()));
  residency.holdAround({});
  EXPECT_TRUE(residency.held().empty());
  EXPECT_TRUE(residency.locate({}, places.data()));
}

class MapFile : public testing::Test {
 protected:
  void SetUp() override {
    directory_ = std::filesystem::temp_directory_path() / ("elo_point_map_" + std::to_string(::getpid()));
    std::filesystem::create_directories(directory_);
  }
  void TearDown() override { std::filesystem::remove_all(directory_); }
  std::string path(const std::string& name) const { return (directory_ / name).string(); }

  std::filesystem::path directory_;
};

TEST_F(MapFile, RoundTripsWithAndWithoutNormals) {
  MapCloud map;
  addWall(map, 3.0, 2.0, 2.0, 0.25);
  map.intensity.assign(map.size(), 7.0f);
  writeMapPcd(path("bare.pcd"), map);
  const MapCloud bare = readMapPcd(path("bare.pcd"));
  EXPECT_EQ(bare.points, map.points);
  EXPECT_EQ(bare.intensity, map.intensity);
  EXPECT_TRUE(bare.normals.empty());

  prepareMap(map, 0.6);
  writeMapPcd(path("normals.pcd"), map);
  const MapCloud with_normals = readMapPcd(path("normals.pcd"));
  EXPECT_EQ(with_normals.normals, map.normals);
}

TEST_F(MapFile, SomeNormalFieldsButNotAllIsAnError) {
  std::ofstream file(path("partial.pcd"));
  file << "VERSION .7\nFIELDS x y z normal_x\nSIZE 4 4 4 4\nTYPE F F F F\nCOUNT 1 1 1 1\nWIDTH 1\nHEIGHT 1\n"
          "VIEWPOINT 0 0 0 1 0 0 0\nPOINTS 1\nDATA ascii\n1 2 3 1\n";
  file.close();
  EXPECT_THROW(readMapPcd(path("partial.pcd")), IoError);
  EXPECT_THROW(readMapPcd(path("missing.pcd")), IoError);
}

// Pixels of the rendered range image that hold a point, all on the wall.
size_t renderedWallPixels(const Config& config, const std::shared_ptr<MapCloud>& map, size_t floor_points) {
  std::unique_ptr<Backend> backend = makeBackend(config);
  backend->setMap(map);
  std::vector<int32_t> all(map->size());
  std::iota(all.begin(), all.end(), 0);
  backend->renderMap(all, Eigen::Isometry3d(Eigen::Translation3d(0.0, 0.0, config.ground.sensor_height)));
  const Model& model = backend->mapModel();
  size_t wall_pixels = 0;
  for (size_t pixel = 0; pixel < model.nonground.pixelCount(); ++pixel) {
    if (!model.nonground.occupied(pixel)) continue;
    ++wall_pixels;
    EXPECT_NEAR(model.nonground.vertex[pixel].x(), 10.0f, 1e-4f);
    EXPECT_NEAR(model.nonground.normal[pixel].x(), -1.0f, 1e-3f);
  }
  // Every floor point (0.2 m apart: each in a cell of its own) is ground; the wall is not.
  EXPECT_EQ(model.ground.size(), floor_points);
  for (const Vec3f& vertex : model.ground.vertex) EXPECT_NEAR(vertex.z(), -config.ground.sensor_height, 1e-4f);
  return wall_pixels;
}

// A floor 1.73 m below the sensor and a wall 10 m ahead, points 0.2 m apart, rendered from the sensor:
// the wall into the range image with normals facing the sensor, the floor into the BEV map. The wall
// spans 39 degrees either side (440 columns) and from the image's top edge down to -9.3 degrees (35
// rows): its points alone, 0.2 m apart (6.5 columns and 3.3 rows at 10 m), would fill a twentieth of
// those pixels; covering their discs, they fill most.
TEST(MapRendering, WallGoesToTheRangeImageAndFloorToTheBevMap) {
  Config config;
  config.runtime.threads = 2;
  auto map = std::make_shared<MapCloud>();
  addFloor(*map, 30.0, 0.2, 0.0);
  const size_t floor_points = map->size();
  addWall(*map, 10.0, 16.0, 4.0, 0.2);
  prepareMap(*map, config.localization.normal_radius);
  const size_t wall_pixels = 440 * 35;
  const size_t splatted = renderedWallPixels(config, map, floor_points);
  config.localization.splat_radius = 0.0;
  const size_t points_alone = renderedWallPixels(config, map, floor_points);
  std::printf("wall pixels filled: %zu of %zu splatted, %zu by the points alone\n", splatted, wall_pixels, points_alone);
  EXPECT_GE(splatted, wall_pixels * 3 / 4);
  EXPECT_LE(points_alone, wall_pixels / 10);
}

}  // namespace
}  // namespace elo
