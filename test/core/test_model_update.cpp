// The model update of Sec. III-D: the closer surface wins and keeps its oldest point, empty pixels keep the
// model, old points expire.
#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <map>
#include <random>

#include "core/cpu/stages.hpp"

namespace elo {
namespace {

struct Fixture {
  Config config;
  SphericalProjection spherical = SphericalProjection::fromConfig(config.sensor);
  BevProjection bev = BevProjection::fromConfig(config.bev);
  cpu::SphericalFusionScratch scratch;
  cpu::GroundMapScratch ground_scratch;

  // The spherical model, a scan and the fused result: empty, of the projection's size.
  SphericalImage model, fused;
  ScanImage scan;

  Fixture() {
    scratch.resize(static_cast<size_t>(spherical.rows) * spherical.cols);
    model.resize(spherical.rows, spherical.cols);
    fused.resize(spherical.rows, spherical.cols);
    scan.resize(spherical.rows, spherical.cols);
  }

  size_t pixelOf(const Vec3f& p) const {
    int row = 0;
    int col = 0;
    EXPECT_TRUE(spherical.pixelOf(p, row, col));
    return static_cast<size_t>(row) * spherical.cols + col;
  }
  // The BEV cell of a ground point, which must lie in the map.
  int32_t cellOf(const Vec3f& p) const {
    int row = 0;
    int col = 0;
    EXPECT_TRUE(bev.cellOf(p, row, col));
    return row * bev.cols + col;
  }
  // An empty BEV map of the configured grid.
  BevImage emptyBevMap() const {
    BevImage map;
    map.resize(bev.rows, bev.cols);
    return map;
  }
  // Fuses `scan` into `model` at time `now`, leaving the result in `fused`.
  void fuse(const Eigen::Isometry3d& model_from_scan, float now) {
    const auto fusion = ModelFusion::fromConfig(config.model, now);
    cpu::fuseSphericalModel(model, scan, spherical, model_from_scan, fusion, scratch, fused);
  }
  static void put(SphericalImage& image, size_t pixel, const Vec3f& p, float stamp) {
    image.vertex[pixel] = p;
    image.range[pixel] = p.norm();
    image.normal[pixel] = -p.normalized();
    image.stamp[pixel] = stamp;
  }
};

TEST(ModelUpdate, CloserPointWinsAndEmptyScanPixelsKeepTheModel) {
  Fixture f;
  SphericalImage& model = f.model;
  ScanImage& scan = f.scan;
  SphericalImage& fused = f.fused;

  const Vec3f direction_a = Vec3f(1.0f, 0.1f, -0.05f).normalized();
  const Vec3f direction_b = Vec3f(0.2f, 1.0f, -0.05f).normalized();
  const Vec3f direction_c = Vec3f(-1.0f, 0.3f, -0.02f).normalized();
  const size_t a = f.pixelOf(direction_a * 20.0f);
  const size_t b = f.pixelOf(direction_b * 8.0f);
  const size_t c = f.pixelOf(direction_c * 15.0f);
  Fixture::put(model, a, direction_a * 20.0f, 0.0f);  // scan sees something closer here
  Fixture::put(model, b, direction_b * 8.0f, 0.0f);   // the model is closer here
  Fixture::put(model, c, direction_c * 15.0f, 0.0f);  // the scan sees nothing here
  for (const auto& [pixel, point] : {std::pair{a, direction_a * 12.0f}, std::pair{b, direction_b * 30.0f}}) {
    Fixture::put(scan.image, pixel, point, 1.0f);
    scan.label[pixel] = PixelLabel::nonground;
  }

  f.fuse(Eigen::Isometry3d::Identity(), 1.0f);
  EXPECT_FLOAT_EQ(fused.range[a], 12.0f);
  EXPECT_FLOAT_EQ(fused.stamp[a], 1.0f);
  EXPECT_FLOAT_EQ(fused.range[b], 8.0f);
  EXPECT_FLOAT_EQ(fused.stamp[b], 0.0f);
  EXPECT_FLOAT_EQ(fused.range[c], 15.0f);
  EXPECT_EQ(fused.countOccupied(), 3u);
}

TEST(ModelUpdate, OneSurfaceSeenAgainKeepsTheOlderPointUnlessTheRuleIsLiteral) {
  Fixture f;
  const Vec3f direction = Vec3f(1.0f, 0.2f, -0.05f).normalized();
  const size_t pixel = f.pixelOf(direction * 20.0f);
  Fixture::put(f.model, pixel, direction * 20.0f, 0.0f);
  Fixture::put(f.scan.image, pixel, direction * 19.8f, 1.0f);  // 0.2 m closer: within the 0.3 m default
  f.scan.label[pixel] = PixelLabel::nonground;

  f.fuse(Eigen::Isometry3d::Identity(), 1.0f);
  EXPECT_FLOAT_EQ(f.fused.range[pixel], 20.0f);
  EXPECT_FLOAT_EQ(f.fused.stamp[pixel], 0.0f);

  f.config.model.same_surface_distance = 0.0;  // the paper's literal rule: the closer always wins
  f.fuse(Eigen::Isometry3d::Identity(), 1.0f);
  EXPECT_FLOAT_EQ(f.fused.range[pixel], 19.8f);
  EXPECT_FLOAT_EQ(f.fused.stamp[pixel], 1.0f);
}

// A wall 20 m away seen 20 times from the same place with 2 cm range noise. Literally, closer-wins keeps
// the nearest of the 20 ranges of each pixel, about 1.87 sigma (37 mm) in front of the wall; with the
// same-surface rule each pixel keeps its first range and the wall stays where it is.
TEST(ModelUpdate, NoisyRangesOfOneSurfaceDoNotPullTheModelTowardsTheSensor) {
  const auto model_offset = [](double same_surface_distance) {
    Fixture f;
    f.config.model.same_surface_distance = same_surface_distance;
    std::mt19937 random(3);
    std::normal_distribution<float> noise(0.0f, 0.02f);
    std::map<size_t, Vec3f> wall;  // pixel -> direction of its beam
    for (int i = 0; i < 1000; ++i) {
      const Vec3f direction = Vec3f(1.0f, -0.5f + 0.001f * i, -0.1f + 0.0002f * (i % 500)).normalized();
      wall.emplace(f.pixelOf(direction * 20.0f), direction);
    }
    for (int frame = 0; frame < 20; ++frame) {
      f.scan.image.clear();
      for (const auto& [pixel, direction] : wall) {
        Fixture::put(f.scan.image, pixel, direction * (20.0f + noise(random)), 0.1f * frame);
        f.scan.label[pixel] = PixelLabel::nonground;
      }
      f.fuse(Eigen::Isometry3d::Identity(), 0.1f * frame);
      std::swap(f.model, f.fused);
    }
    double sum = 0.0;
    for (const auto& [pixel, direction] : wall) sum += f.model.range[pixel] - 20.0;
    return sum / static_cast<double>(wall.size());
  };
  EXPECT_LT(model_offset(0.0), -0.030) << "the literal rule keeps the nearest of the noisy ranges";
  EXPECT_NEAR(model_offset(0.3), 0.0, 0.003);
}

TEST(ModelUpdate, ModelPointsMoveIntoTheNewFrameAndExpire) {
  Fixture f;
  SphericalImage& model = f.model;
  SphericalImage& fused = f.fused;
  const Vec3f fresh(20.0f, 2.0f, 0.5f);
  const Vec3f stale(-10.0f, 6.0f, 0.2f);
  Fixture::put(model, f.pixelOf(fresh), fresh, 5.0f);
  Fixture::put(model, f.pixelOf(stale), stale, 0.5f);
  // The sensor moved 2 m forward: the model must appear 2 m closer along x.
  Eigen::Isometry3d model_from_scan = Eigen::Isometry3d::Identity();
  model_from_scan.translation() << 2.0, 0.0, 0.0;
  f.fuse(model_from_scan, 11.0f);
  const Vec3f moved = fresh - Vec3f(2.0f, 0.0f, 0.0f);
  const size_t pixel = f.pixelOf(moved);
  ASSERT_TRUE(fused.occupied(pixel));
  EXPECT_TRUE(fused.vertex[pixel].isApprox(moved));
  EXPECT_EQ(fused.countOccupied(), 1u) << "the point observed 10.5 s ago must have expired";
}

TEST(ModelUpdate, GroundMapKeepsTheOldestPointOfTheRoadAndExpiresOldOnes) {
  Fixture f;
  BevImage model = f.emptyBevMap();
  BevImage scan_ground = f.emptyBevMap();
  BevImage fused = f.emptyBevMap();
  const Vec3f kept(10.02f, 3.03f, -1.73f);
  const Vec3f old(-7.0f, 1.0f, -1.73f);
  model.keepCloser(f.cellOf(kept), kept, 4.0f);
  model.keepCloser(f.cellOf(old), old, 0.0f);
  const Vec3f closer(10.01f, 3.02f, -1.72f);  // the same road in the same cell, a little nearer the sensor
  scan_ground.keepCloser(f.cellOf(closer), closer, 12.0f);

  const auto fuseAt12 = [&] {
    cpu::fuseGroundModel(model, scan_ground, f.bev, Eigen::Isometry3d::Identity(),
                         ModelFusion::fromConfig(f.config.model, 12.0f), f.ground_scratch, fused);
  };
  fuseAt12();
  ASSERT_EQ(fused.size(), 1u) << "the point observed 12 s ago must have expired";
  const int32_t point = fused.point_of_cell[f.cellOf(kept)];
  ASSERT_GE(point, 0);
  EXPECT_TRUE(fused.vertex[point].isApprox(kept));
  EXPECT_FLOAT_EQ(fused.stamp[point], 4.0f);
  EXPECT_FALSE(fused.occupied(f.cellOf(old)));

  f.config.model.same_surface_distance = 0.0;  // the paper's literal rule: the closer always wins
  fuseAt12();
  EXPECT_TRUE(fused.vertex[fused.point_of_cell[f.cellOf(kept)]].isApprox(closer));
}

// Within one scan every point has the same age: of the points of one surface in a cell the source the
// hash ranks first stays, whatever its noise or its place (here source 7, the farther point); the literal
// rule keeps the nearest.
TEST(ModelUpdate, GroundCellOfOneScanKeepsItsFirstSourceOnTheClosestSurface) {
  ASSERT_LT(scrambledSource(7), scrambledSource(9));
  Fixture f;
  BevImage map = f.emptyBevMap();
  const Vec3f farther(10.05f, 3.04f, -1.75f);
  const Vec3f nearer(10.01f, 3.01f, -1.72f);
  const int32_t cell = f.cellOf(farther);
  f.ground_scratch.offers = {{cell, nearer, 1.0f, 9}, {cell, farther, 1.0f, 7}};
  cpu::fillGroundMap(0.3f, f.ground_scratch, map);
  ASSERT_EQ(map.size(), 1u);
  EXPECT_EQ(map.vertex[0], farther);
  EXPECT_FLOAT_EQ(map.range[0], farther.norm());
  cpu::fillGroundMap(0.0f, f.ground_scratch, map);
  EXPECT_EQ(map.vertex[0], nearer);
}

// Both backends give a cell the next slot when it is first offered a point, so their maps agree element
// by element (bev_map.cu); the CPU's fill must keep that order whatever point a cell keeps.
TEST(ModelUpdate, GroundMapSlotsFollowEachCellsFirstOffer) {
  Fixture f;
  BevImage map = f.emptyBevMap();
  const Vec3f b_far(3.05f, 1.02f, -1.73f);
  const Vec3f b_near(3.01f, 1.01f, -0.50f);  // another surface in the same cell, 0.4 m nearer
  const Vec3f a_old(8.02f, 2.02f, -1.73f);
  const Vec3f a_new(8.01f, 2.01f, -1.71f);  // the same road as a_old
  const Vec3f c(-15.0f, 6.0f, -1.73f);
  const int32_t a = f.cellOf(a_old);
  const int32_t b = f.cellOf(b_far);
  ASSERT_EQ(f.cellOf(a_new), a);
  ASSERT_EQ(f.cellOf(b_near), b);
  ASSERT_GT(f.cellOf(c), a);  // the slots' order is not the cells'
  ASSERT_GT(a, b);
  f.ground_scratch.offers = {
      {f.cellOf(c), c, 2.0f, 0}, {b, b_far, 1.0f, 1}, {a, a_new, 2.0f, 2}, {b, b_near, 2.0f, 3}, {a, a_old, 1.0f, 4}};
  cpu::fillGroundMap(0.3f, f.ground_scratch, map);
  ASSERT_EQ(map.cell, (std::vector<int32_t>{f.cellOf(c), b, a}));
  for (int32_t slot = 0; slot < 3; ++slot) EXPECT_EQ(map.point_of_cell[map.cell[slot]], slot);
  EXPECT_EQ(map.vertex[0], c);
  EXPECT_EQ(map.vertex[1], b_near) << "a nearer surface replaces what it hides";
  EXPECT_EQ(map.vertex[2], a_old) << "one surface seen again keeps its oldest point";
  EXPECT_EQ(map.stamp, (std::vector<float>{2.0f, 2.0f, 1.0f}));
  for (int32_t slot = 0; slot < 3; ++slot) EXPECT_FLOAT_EQ(map.range[slot], map.vertex[slot].norm());
}

// Many offers crowding a few hundred cells, some offered to no cell: up to two threads the fill takes each
// offer in turn, from three on it groups them by bands of cells first (bev_map.cpp). Both must give the
// map the rules give, computed here cell by cell: slots in the order of each cell's first offer, each
// keeping the oldest offer (among equals the source the hash ranks first) within the surface distance of
// the closest.
TEST(ModelUpdate, GroundMapIsTheRulesMapOnOneThreadAndOnMany) {
  Fixture f;
  constexpr float kSameSurface = 0.3f;
  std::mt19937 random(7);
  std::uniform_int_distribution<int32_t> cell_index(-40, 399);  // negative: offered to no cell
  std::uniform_real_distribution<float> height(-2.0f, -1.2f);
  std::uniform_int_distribution<int> age(0, 3);
  std::vector<cpu::GroundOffer>& offers = f.ground_scratch.offers;
  std::vector<uint32_t> sources(60000);
  for (uint32_t i = 0; i < sources.size(); ++i) sources[i] = 3 * i + 1;
  std::shuffle(sources.begin(), sources.end(), random);  // lower sources come later as often as earlier
  for (const uint32_t source : sources) {
    const int32_t index = cell_index(random);
    const int32_t cell = index < 0 ? -1 : 5000 + 997 * index;  // over many bands of cells
    const Vec3f point(10.0f + 0.001f * static_cast<float>(index), 2.0f, height(random));
    offers.emplace_back(cell, point, static_cast<float>(age(random)), source);
  }
  // The rules, cell by cell.
  std::vector<int32_t> expected_cells;
  std::map<int32_t, float> closest;
  std::map<int32_t, const cpu::GroundOffer*> kept;
  for (const cpu::GroundOffer& offer : offers) {
    if (offer.cell < 0) continue;
    if (closest.count(offer.cell) == 0) expected_cells.push_back(offer.cell);
    closest[offer.cell] = closest.count(offer.cell) ? std::min(closest[offer.cell], offer.range) : offer.range;
  }
  for (const cpu::GroundOffer& offer : offers) {
    if (offer.cell < 0 || offer.range > closest[offer.cell] + kSameSurface) continue;
    const cpu::GroundOffer*& best = kept[offer.cell];
    if (best == nullptr || offer.stamp < best->stamp ||
        (offer.stamp == best->stamp && scrambledSource(offer.source) < scrambledSource(best->source))) {
      best = &offer;
    }
  }
  ASSERT_GT(expected_cells.size(), 400u - 5u);

  for (const int threads : {1, 4}) {
    BevImage map = f.emptyBevMap();
    tbb::task_arena(threads).execute([&] {
      cpu::fillGroundMap(kSameSurface, f.ground_scratch, map);
      cpu::fillGroundMap(kSameSurface, f.ground_scratch, map);  // a full map is emptied first
    });
    ASSERT_EQ(map.cell, expected_cells) << threads << " threads";
    for (size_t slot = 0; slot < map.size(); ++slot) {
      const cpu::GroundOffer& best = *kept[map.cell[slot]];
      EXPECT_EQ(map.point_of_cell[map.cell[slot]], static_cast<int32_t>(slot));
      EXPECT_EQ(map.vertex[slot], best.vertex) << threads << " threads, slot " << slot;
      EXPECT_EQ(map.stamp[slot], best.stamp);
      EXPECT_EQ(map.range[slot], best.range);
    }
    EXPECT_EQ(std::count_if(map.point_of_cell.begin(), map.point_of_cell.end(), [](int32_t p) { return p >= 0; }),
              static_cast<std::ptrdiff_t>(map.size()));
  }
}

// The fused map lists the model's surviving points in their order, then the scan's new cells.
TEST(ModelUpdate, FusedGroundMapKeepsTheModelsOrderThenTheScans) {
  Fixture f;
  BevImage model = f.emptyBevMap();
  BevImage scan_ground = f.emptyBevMap();
  BevImage fused = f.emptyBevMap();
  const Vec3f y(5.0f, 9.0f, -1.73f);
  const Vec3f x(12.0f, -3.0f, -1.73f);
  const Vec3f expired(-20.0f, 0.0f, -1.73f);
  const Vec3f z(30.0f, 1.0f, -1.73f);
  const Vec3f w(-6.0f, -6.0f, -1.73f);
  model.keepCloser(f.cellOf(expired), expired, 0.0f);
  model.keepCloser(f.cellOf(y), y, 5.0f);
  model.keepCloser(f.cellOf(x), x, 5.0f);
  model.keepCloser(f.cellOf(z), z, 5.0f);
  scan_ground.keepCloser(f.cellOf(w), w, 12.0f);
  scan_ground.keepCloser(f.cellOf(x), x + Vec3f(0.0f, 0.0f, 0.01f), 12.0f);
  cpu::fuseGroundModel(model, scan_ground, f.bev, Eigen::Isometry3d::Identity(),
                       ModelFusion::fromConfig(f.config.model, 12.0f), f.ground_scratch, fused);
  ASSERT_GT(f.cellOf(y), f.cellOf(z));  // the slots' order is not the cells'
  EXPECT_EQ(fused.cell, (std::vector<int32_t>{f.cellOf(y), f.cellOf(x), f.cellOf(z), f.cellOf(w)}));
  EXPECT_EQ(fused.vertex, (std::vector<Vec3f>{y, x, z, w}));
  EXPECT_EQ(fused.stamp, (std::vector<float>{5.0f, 5.0f, 5.0f, 12.0f}));
}

TEST(ModelUpdate, GroundMapMovesWithTheSensorAndStaysBounded) {
  Fixture f;
  BevImage model = f.emptyBevMap();
  BevImage fused = f.emptyBevMap();
  BevImage scan_ground = f.emptyBevMap();
  Eigen::Isometry3d step = Eigen::Isometry3d::Identity();
  step.translation() << 1.0, 0.0, 0.0;  // the sensor advances 1 m a frame
  for (int frame = 0; frame < 1000; ++frame) {
    scan_ground.clear();
    for (int i = 0; i < 50; ++i) {
      const Vec3f p(-10.0f + 0.4f * i, 0.0f, -1.73f);
      scan_ground.keepCloser(f.cellOf(p), p, 0.1f * frame);
    }
    cpu::fuseGroundModel(model, scan_ground, f.bev, step, ModelFusion::fromConfig(f.config.model, 0.1f * frame),
                         f.ground_scratch, fused);
    std::swap(model, fused);
  }
  // A point seen at x = 0 one frame ago now lies at x = -1.
  EXPECT_TRUE(model.occupied(f.cellOf(Vec3f(-1.0f, 0.0f, -1.73f))));
  // 10 s at 1 m a frame: at most 100 frames of 50 points survive, and the grid never grows.
  EXPECT_LE(model.size(), 100u * 50u);
  EXPECT_EQ(model.point_of_cell.size(), static_cast<size_t>(f.bev.rows) * f.bev.cols);
}

}  // namespace
}  // namespace elo
