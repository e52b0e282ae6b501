// The per-element math both backends run (src/core/common), tested on the CPU. The CPU backend calls
// most of it, so the stage tests cover it too; these tests cover what is new or only the CUDA backend
// runs: the ported eigen-solver, the keys, transforms and point-to-plane terms, windowNormal(), the
// scalar normal estimator of the GPU, against the CPU backend's vectorised one, the GPU's tiles of the scan
// it reads its windows from, the GPU's per-pixel ground labels against the CPU's column walk, and the
// rules of localization's map rendering.
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <cstring>
#include <random>
#include <set>

#include "analytic_scene.hpp"
#include "core/common/association.hpp"
#include "core/common/closest_wins_key.hpp"
#include "core/common/model_update.hpp"
#include "core/common/eigen_interop.hpp"
#include "core/common/ground.hpp"
#include "core/common/map_render.hpp"
#include "core/common/normals.hpp"
#include "core/common/point_to_plane.hpp"
#include "core/cpu/eigen_lanes.hpp"
#include "core/cpu/image_views.hpp"
#include "core/cpu/packed_sums.hpp"
#include "core/cuda/normal_tile.hpp"
#include "elo/pipeline/backend.hpp"

namespace elo {
namespace {

SymmetricMatrix3 covarianceOf(const std::vector<Float3>& points) {
  PointMoments moments;
  for (const Float3& p : points) moments.add(p);
  return moments.covariance();
}

Eigen::Matrix3f toEigen(const SymmetricMatrix3& m) {
  Eigen::Matrix3f matrix;
  matrix << m.xx, m.xy, m.xz, m.xy, m.yy, m.yz, m.xz, m.yz, m.zz;
  return matrix;
}

// Points scattered with standard deviations `spread` along three random orthogonal axes.
std::vector<Float3> scatteredPoints(std::mt19937& random, const Eigen::Vector3f& spread, int count = 40) {
  std::normal_distribution<float> gaussian(0.0f, 1.0f);
  const Eigen::Matrix3f axes = Eigen::Quaternionf::UnitRandom().toRotationMatrix();
  std::vector<Float3> points;
  for (int i = 0; i < count; ++i) {
    const Eigen::Vector3f local(spread.x() * gaussian(random), spread.y() * gaussian(random), spread.z() * gaussian(random));
    points.push_back(toFloat3(axes * local + Eigen::Vector3f(0.3f, -0.2f, 0.1f)));
  }
  return points;
}

TEST(SymmetricEigen, ArctangentSineAndCosineAreAccurate) {
  for (int i = 0; i <= 10000; ++i) {
    const float angle = static_cast<float>(M_PI) * i / 10000.0f;
    const float y = std::fabs(std::sin(angle));  // at pi, sinf is a hair below zero
    const float x = std::cos(angle);
    EXPECT_NEAR(detail::upperArctangent2(y, x), std::atan2(static_cast<double>(y), x), 4e-7);
    const float small = static_cast<float>(M_PI / 4) * (i / 10000.0f);
    EXPECT_NEAR(detail::sineNearZero(small), std::sin(static_cast<double>(small)), 2e-7);
    EXPECT_NEAR(detail::cosineNearZero(small), std::cos(static_cast<double>(small)), 2e-7);
  }
}

// Against Eigen's iterative solver in double. Like Eigen's closed form in float, ours keeps float
// accuracy for an eigenvalue that stands apart, and about half of it for two that nearly coincide.
TEST(SymmetricEigen, MatchesADoublePrecisionSolver) {
  std::mt19937 random(7);
  const Eigen::Vector3f spreads[] = {{1.0f, 0.5f, 0.2f}, {0.3f, 0.3f, 0.001f}, {2.0f, 0.01f, 0.01f}, {0.4f, 0.2f, 0.0f}};
  for (int trial = 0; trial < 400; ++trial) {
    const SymmetricMatrix3 covariance = covarianceOf(scatteredPoints(random, spreads[trial % 4]));
    const SymmetricEigen ours = symmetricEigen(covariance);
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> reference(toEigen(covariance).cast<double>());
    const Eigen::Vector3d exact = reference.eigenvalues();
    const double largest = exact(2);
    for (int i = 0; i < 3; ++i) {
      const double gap = std::min(i > 0 ? exact(i) - exact(i - 1) : largest, i < 2 ? exact(i + 1) - exact(i) : largest);
      EXPECT_NEAR(ours.eigenvalues[i], exact(i), (gap > 1e-2 * largest ? 2e-6 : 1e-3) * largest) << "trial " << trial;
    }
    EXPECT_NEAR(norm(ours.smallest), 1.0f, 1e-5f);
    // The smallest eigenvector is defined where the smallest eigenvalue stands apart.
    if (exact(1) - exact(0) > 1e-2 * largest) {
      EXPECT_GT(std::abs(toVec3f(ours.smallest).cast<double>().dot(reference.eigenvectors().col(0))), 1.0 - 1e-5)
          << "trial " << trial;
    }
  }
}

TEST(SymmetricEigen, CollinearAndIsotropicPointsStillGiveAUnitOrthogonalVector) {
  std::mt19937 random(3);
  const std::vector<Float3> line = scatteredPoints(random, {1.0f, 0.0f, 0.0f});
  const SymmetricEigen collinear = symmetricEigen(covarianceOf(line));
  const Float3 direction = line[1] - line[0];
  EXPECT_NEAR(norm(collinear.smallest), 1.0f, 1e-5f);
  EXPECT_NEAR(dot(collinear.smallest, direction / norm(direction)), 0.0f, 1e-3f);
  const SymmetricEigen isotropic = symmetricEigen({2.0f, 0.0f, 0.0f, 2.0f, 0.0f, 2.0f});
  EXPECT_FLOAT_EQ(isotropic.eigenvalues[0], 2.0f);
  EXPECT_FLOAT_EQ(isotropic.eigenvalues[2], 2.0f);
  EXPECT_NEAR(norm(isotropic.smallest), 1.0f, 1e-6f);
}

// The CPU's 8-lane solve (eigen_lanes.hpp) against symmetricEigen() itself, bit for bit: planes, lines,
// blobs and nearly coincident eigenvalues of random point sets, and the edge cases of the branches (a
// zero matrix, equal eigenvalues, diagonal matrices whose largest entry is in each column, two equal
// eigenvalues, points all in one spot), in lanes of every fill.
TEST(SymmetricEigen, EightLanesGiveTheScalarSolveBitForBit) {
  std::mt19937 random(5);
  const Eigen::Vector3f spreads[] = {{1.0f, 0.5f, 0.2f},  {0.3f, 0.3f, 0.001f}, {2.0f, 0.01f, 0.01f},
                                     {0.4f, 0.2f, 0.0f},  {1.0f, 1.0f, 1.0f},   {0.5f, 0.5f, 0.0f},
                                     {1.0f, 0.0f, 0.0f},  {1e-4f, 1e-4f, 1e-5f}};
  std::vector<SymmetricMatrix3> matrices = {
      {0.0f, 0.0f, 0.0f, 0.0f, 0.0f, 0.0f},  {2.0f, 0.0f, 0.0f, 2.0f, 0.0f, 2.0f},
      {3.0f, 0.0f, 0.0f, 1.0f, 0.0f, 2.0f},  {1.0f, 0.0f, 0.0f, 3.0f, 0.0f, 2.0f},
      {1.0f, 0.0f, 0.0f, 2.0f, 0.0f, 3.0f},  {1.0f, 0.0f, 0.0f, 1.0f, 0.0f, 4.0f},
      {4.0f, 0.0f, 0.0f, 1.0f, 0.0f, 1.0f},  {1.0f, 0.5f, 0.0f, 1.0f, 0.0f, 0.5f},
      covarianceOf(std::vector<Float3>(6, Float3{1.0f, 2.0f, 3.0f}))};
  for (int trial = 0; trial < 4000; ++trial) {
    matrices.push_back(covarianceOf(scatteredPoints(random, spreads[trial % 8], 5 + trial % 60)));
  }
  const auto bits = [](float value) {
    uint32_t b;
    std::memcpy(&b, &value, sizeof(b));
    return b;
  };
  size_t compared = 0;
  int count = 0;
  for (size_t first = 0; first < matrices.size(); first += static_cast<size_t>(count)) {
    count = static_cast<int>(std::min<size_t>(cpu::kEigenLanes - first % 3, matrices.size() - first));  // 6 to 8
    SymmetricEigen lanes[cpu::kEigenLanes];
    cpu::symmetricEigens(matrices.data() + first, count, lanes);
    for (int lane = 0; lane < count; ++lane) {
      const SymmetricEigen scalar = symmetricEigen(matrices[first + lane]);
      for (int i = 0; i < 3; ++i) {
        EXPECT_EQ(bits(lanes[lane].eigenvalues[i]), bits(scalar.eigenvalues[i])) << "matrix " << first + lane;
      }
      EXPECT_EQ(bits(lanes[lane].smallest.x), bits(scalar.smallest.x)) << "matrix " << first + lane;
      EXPECT_EQ(bits(lanes[lane].smallest.y), bits(scalar.smallest.y)) << "matrix " << first + lane;
      EXPECT_EQ(bits(lanes[lane].smallest.z), bits(scalar.smallest.z)) << "matrix " << first + lane;
      ++compared;
    }
  }
  EXPECT_EQ(compared, matrices.size());
}

TEST(PlaneFit, RecoversAPlaneAndItsFlatness) {
  std::mt19937 random(11);
  const std::vector<Float3> plane = scatteredPoints(random, {0.5f, 0.3f, 0.0f});
  PointMoments moments;
  for (const Float3& p : plane) moments.add(p - plane[0]);
  const PlaneFit fit = fitPlane(moments);
  ASSERT_TRUE(fit.valid);
  EXPECT_LT(fit.curvature, 1e-5f);
  EXPECT_LT(std::abs(dot(fit.normal, plane[1] - plane[0])), 1e-4f);
  EXPECT_LT(std::abs(dot(fit.normal, plane[2] - plane[0])), 1e-4f);
  PointMoments two;
  two.add(plane[0]);
  two.add(plane[1]);
  EXPECT_FALSE(fitPlane(two).valid);
}

TEST(GroundPlaneNormal, FitsATiltedPatchAndRejectsASpot) {
  // z = 0.05 x - 0.02 y - 1.73: normal (-0.05, 0.02, 1), normalised; points 10 cm apart across.
  std::vector<Float3> patch;
  for (int i = 0; i < 5; ++i) {
    const float x = 10.0f + 0.1f * i;
    const float y = 2.0f + 0.1f * ((i * 3) % 5);
    patch.push_back({x, y, 0.05f * x - 0.02f * y - 1.73f});
  }
  const Float3 normal = groundPlaneNormal(patch.data(), 5, patch[0]);
  const Eigen::Vector3f expected = Eigen::Vector3f(-0.05f, 0.02f, 1.0f).normalized();
  EXPECT_GT(toVec3f(normal).dot(expected), 1.0f - 1e-6f);
  std::vector<Float3> spot(5, Float3{10.0f, 2.0f, -1.73f});
  EXPECT_TRUE(isZero(groundPlaneNormal(spot.data(), 5, spot[0])));
}

// The points of one ring give the road's slope along the ring, and a plane level across it: here a ring
// along y on a road rising 3 % along y, its normal (0, -0.03, 1).
TEST(GroundPlaneNormal, ARingGivesItsSlopeAlongAndLevelAcross) {
  std::vector<Float3> ring;
  for (int i = 0; i < 5; ++i) ring.push_back({10.0f, 2.0f + 0.05f * i, -1.73f + 0.03f * 0.05f * i});
  const Float3 normal = groundPlaneNormal(ring.data(), 5, ring[0]);
  EXPECT_GT(toVec3f(normal).dot(Eigen::Vector3f(0.0f, -0.03f, 1.0f).normalized()), 1.0f - 1e-6f);
}

// A ring ahead of the sensor on flat road, its points moved 2-3 cm along the beam (10 deg down) by range
// noise: spread across the ring, but along the beam, so that a plane through them all leans towards the
// sensor by some degrees. As one ring it stays level across: within 1 deg of the vertical (what is left
// is the noise's share along the ring, of either sign).
TEST(GroundPlaneNormal, ARingSpreadByRangeNoiseAlongTheBeamsDoesNotLean) {
  const float along[] = {0.02f, -0.03f, 0.01f, 0.03f, -0.02f};
  const float slope = std::tan(10.0f * static_cast<float>(M_PI) / 180.0f);
  std::vector<Float3> ring;
  for (int i = 0; i < 5; ++i) ring.push_back({10.0f + along[i], 2.0f + 0.05f * i, -1.73f - slope * along[i]});
  const Float3 normal = groundPlaneNormal(ring.data(), 5, ring[0]);
  EXPECT_GT(normal.z, std::cos(1.0f * static_cast<float>(M_PI) / 180.0f));
}

// A GroundMap of a small grid in which chosen cells hold a point numbered like the cell.
struct NumberedCells {
  std::vector<int32_t> point_of_cell;
  int32_t pointOfCell(int cell) const { return point_of_cell[cell]; }
};

// The ring search and the ground normals' fits visit a ring's cells row by row and, within a row, column
// by column (the order decides ties between equally distant points): every cell at that Chebyshev
// distance inside the grid, once, and no other, wherever the ring is clipped by the grid's edges.
TEST(RingOfCells, VisitsEachOccupiedCellAtThatDistanceOnceInRowMajorOrder) {
  BevConfig config;
  config.half_length = 0.65;  // 13 x 9 cells
  config.half_width = 0.45;
  const BevProjection bev = BevProjection::fromConfig(config);
  std::mt19937 random(5);
  std::bernoulli_distribution occupied(0.7);
  NumberedCells map;
  for (int cell = 0; cell < bev.rows * bev.cols; ++cell) {
    map.point_of_cell.push_back(occupied(random) ? cell : -1);
  }
  for (int row = 0; row < bev.rows; ++row) {
    for (int col = 0; col < bev.cols; ++col) {
      for (int ring = 0; ring <= 14; ++ring) {
        std::vector<int32_t> expected;  // row-major order is increasing cell number
        for (int cell = 0; cell < bev.rows * bev.cols; ++cell) {
          const int distance = std::max(std::abs(cell / bev.cols - row), std::abs(cell % bev.cols - col));
          if (distance == ring && map.point_of_cell[cell] >= 0) expected.push_back(cell);
        }
        std::vector<int32_t> visited;
        auto visit = [&](int32_t point) { visited.push_back(point); };
        forEachPointOnRing(map, bev, row, col, ring, visit);
        ASSERT_EQ(visited, expected) << "row " << row << ", col " << col << ", ring " << ring;
      }
    }
  }
}

TEST(ClosestWinsKey, CloserWinsTiesGoToTheLowerSourceAndNoneLosesToAll) {
  EXPECT_LT(closestWinsKey(4.9f, 1000), closestWinsKey(5.0f, 3));
  EXPECT_LT(closestWinsKey(5.0f, 3), closestWinsKey(5.0f, 4));
  EXPECT_LT(closestWinsKey(119.9f, ~uint32_t{0} - 1), kNoClosestKey);
  const ClosestKey key = closestWinsKey(12.375f, 98765);
  EXPECT_EQ(closestWinsSource(key), 98765u);
  EXPECT_EQ(closestWinsRange(key), 12.375f);
}

Eigen::Isometry3d somePose() {
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = (Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitZ()) * Eigen::AngleAxisd(-0.05, Eigen::Vector3d::UnitX()))
                      .toRotationMatrix();
  pose.translation() << 0.7, -0.1, 0.02;
  return pose;
}

TEST(Rigid3f, AppliesTheEigenTransform) {
  const Eigen::Isometry3d pose = somePose();
  const Rigid3f rigid = toRigid3f(pose);
  const Eigen::Vector3f p(12.0f, -3.5f, -1.6f);
  EXPECT_TRUE(toVec3f(rigid.apply(toFloat3(p))).isApprox((pose * p.cast<double>()).cast<float>(), 1e-6f));
  EXPECT_TRUE(toVec3f(rigid.rotate(toFloat3(p))).isApprox((pose.linear() * p.cast<double>()).cast<float>(), 1e-6f));
}

TEST(PointToPlane, ResidualJacobianAndGemanMcClureWeight) {
  const Float3 moved{10.0f, 2.0f, 0.5f};
  const Float3 vertex{10.1f, 2.0f, 0.4f};
  const Float3 normal{-1.0f, 0.0f, 0.0f};
  const PointToPlane term = pointToPlane(moved, vertex, normal, 0.0);
  EXPECT_NEAR(term.residual, 0.1, 1e-6);
  EXPECT_EQ(term.weight, 1.0);
  const Float3 moment = cross(moved, normal);
  const double expected[6] = {-1.0, 0.0, 0.0, moment.x, moment.y, moment.z};
  for (int i = 0; i < 6; ++i) EXPECT_EQ(term.jacobian[i], expected[i]);
  EXPECT_DOUBLE_EQ(gemanMcClureWeight(0.0, 0.1), 1.0);
  EXPECT_DOUBLE_EQ(gemanMcClureWeight(0.1, 0.1), 0.25);  // (s^2 / (s^2 + e^2))^2 at e = s
}

TEST(PointToPlane, ANearCorrespondenceWeighsItsRangeOverTheNearRange) {
  EXPECT_EQ(nearWeight(9.0f, 45.0f), static_cast<double>(9.0f / 45.0f));
  EXPECT_EQ(nearWeight(45.0f, 45.0f), 1.0);
  EXPECT_EQ(nearWeight(80.0f, 45.0f), 1.0);
  EXPECT_EQ(nearWeight(3.0f, 0.0f), 1.0);  // off
  const Float3 moved{10.0f, 2.0f, 0.5f};
  const Float3 vertex{10.1f, 2.0f, 0.4f};
  const Float3 normal{-1.0f, 0.0f, 0.0f};
  const float scan_range = 5.0f;
  const PointToPlane plain = pointToPlane(moved, vertex, normal, 0.1);
  const PointToPlane near = nongroundTerm(moved, vertex, normal, scan_range, 0.1, 10.0f);
  EXPECT_EQ(near.weight, plain.weight * 0.5);
  EXPECT_EQ(near.residual, plain.residual);
  for (int i = 0; i < 6; ++i) EXPECT_EQ(near.jacobian[i], plain.jacobian[i]);
  EXPECT_EQ(nongroundTerm(moved, vertex, normal, scan_range, 0.1, 0.0f).weight, plain.weight);
}

// The CPU's 4-wide accumulator adds each packed value the same products in the same order as the shared
// scalar one, so its sums are the same bit for bit.
// The model update's second round (model_update.hpp): the older offer wins; equal ages fall to the source
// a bijective hash ranks first, which each key gives back. Of neighbouring sources (neighbouring columns)
// either wins about as often: a tie no longer keeps the counter-clockwise point (issue 31).
TEST(OldestWinsKey, OlderWinsAndEqualAgesFallToAHashOfTheSource) {
  EXPECT_LT(oldestWinsKey(1.0f, 900000), oldestWinsKey(1.1f, 3));
  int lower_wins = 0;
  constexpr uint32_t kPairs = 20000;
  for (uint32_t source = 0; source < kPairs; ++source) {
    for (const uint32_t s : {source, ~source, source * 2654435761u}) {
      ASSERT_EQ(unscrambledSource(scrambledSource(s)), s);
      ASSERT_EQ(oldestWinsSource(oldestWinsKey(3.5f, s)), s);
    }
    if (oldestWinsKey(2.0f, source) < oldestWinsKey(2.0f, source + 1)) ++lower_wins;
  }
  EXPECT_NEAR(static_cast<double>(lower_wins) / kPairs, 0.5, 0.02);
}

TEST(PackedSums, TheCpusLaneSumsEqualTheSharedScalarSumsBitForBit) {
  std::mt19937 random(7);
  std::uniform_real_distribution<float> coordinate(-30.0f, 30.0f);
  std::uniform_real_distribution<float> offset(-0.2f, 0.2f);
  double scalar[kTermValues] = {};
  cpu::LaneSums lanes;
  for (int i = 0; i < 1000; ++i) {
    const Float3 moved{coordinate(random), coordinate(random), coordinate(random)};
    const Float3 vertex = moved + Float3{offset(random), offset(random), offset(random)};
    const Float3 tilted{offset(random), offset(random), 1.0f};
    const Float3 normal = tilted / norm(tilted);
    const PointToPlane term = pointToPlane(moved, vertex, normal, 0.1);
    addToPackedSums(term, scalar);
    lanes.add(term);
  }
  double from_lanes[kTermValues];
  lanes.copyTo(from_lanes);
  for (int v = 0; v < kTermValues; ++v) {
    EXPECT_NE(scalar[v], 0.0) << "value " << v;
    EXPECT_EQ(from_lanes[v], scalar[v]) << "value " << v;
  }
}

// Normals of the CPU backend's and of windowNormal() / crossProductNormal() over the same scan.
struct NormalComparison {
  size_t cpu_normals = 0;
  size_t presence_differs = 0;
  float largest_difference = 0.0f;  // largest component difference where both have one
};

NormalComparison compareWithScalarEstimator(NormalMethod method, double range_noise) {
  Config config;
  config.normals.method = method;
  config.runtime.threads = 2;
  const test::ScanWithTruth truth =
      test::scanScene(test::streetScene(), config.sensor, Eigen::Isometry3d::Identity(), 0.0, range_noise);
  std::unique_ptr<Backend> backend = makeBackend(config);
  backend->projectScan(truth.cloud, 0.0f);
  backend->segmentGround();
  backend->estimateNormals();
  const ScanImage& scan = backend->scan();
  const cpu::ScanPixels pixels(scan);
  const NormalParams params = NormalParams::fromConfig(config.normals, SphericalProjection::fromConfig(config.sensor));
  NormalComparison comparison;
  for (int pixel = 0; pixel < pixels.rows * pixels.cols; ++pixel) {
    if (!pixels.usable(pixel)) continue;
    const Float3 scalar = pixelNormal(pixels, pixel / pixels.cols, pixel % pixels.cols, params);
    const bool cpu_has = scan.image.hasNormal(pixel);
    comparison.cpu_normals += cpu_has;
    if (cpu_has != !isZero(scalar)) {
      ++comparison.presence_differs;
    } else if (cpu_has) {
      const float difference = (scan.image.normal[pixel] - toVec3f(scalar)).cwiseAbs().maxCoeff();
      comparison.largest_difference = std::max(comparison.largest_difference, difference);
    }
  }
  return comparison;
}

// gatherWindow() forms the window sums in the order and with the roundings of the CPU's vectorised lanes,
// and the plane fit uses basic operations only, so the normals are the same bit for bit.
TEST(SharedNormalEstimator, TheGpusScalarEstimatorGivesTheCpuBackendsNormalsBitForBit) {
  for (const NormalMethod method : {NormalMethod::range_adaptive, NormalMethod::eigen, NormalMethod::cross_product}) {
    for (const double noise : {0.0, 0.02}) {
      const NormalComparison comparison = compareWithScalarEstimator(method, noise);
      SCOPED_TRACE("method " + std::to_string(static_cast<int>(method)) + ", noise " + std::to_string(noise));
      EXPECT_GT(comparison.cpu_normals, 10000u);
      EXPECT_EQ(comparison.presence_differs, 0u);
      EXPECT_EQ(comparison.largest_difference, 0.0f);
    }
  }
}

// Each pixel's normal from its block's tile (normal_tile.hpp), as the CUDA backend's blocks of
// `block_rows` x `block_cols` pixels read it, against pixelNormal() over the whole scan.
struct TileComparison {
  size_t normals = 0;     // pixels with a normal over the whole scan
  size_t differing = 0;   // pixels whose normal from the tile differs in any bit
  size_t misplaced = 0;   // slots whose pixel the tile looks up elsewhere, in a slot holding another pixel
};

TileComparison compareTilesWithWholeScan(const Config& config, int block_rows, int block_cols) {
  const test::ScanWithTruth truth =
      test::scanScene(test::streetScene(), config.sensor, Eigen::Isometry3d::Identity(), 0.0, 0.02);
  std::unique_ptr<Backend> backend = makeBackend(config);
  backend->projectScan(truth.cloud, 0.0f);
  backend->segmentGround();
  const ScanImage& scan = backend->scan();
  const cpu::ScanPixels pixels(scan);
  const NormalParams params = NormalParams::fromConfig(config.normals, SphericalProjection::fromConfig(config.sensor));
  TileComparison comparison;
  for (int block_row = 0; block_row < pixels.rows; block_row += block_rows) {
    for (int block_col = 0; block_col < pixels.cols; block_col += block_cols) {
      const cuda::TileShape shape = cuda::TileShape::around(params, block_row, block_col, block_rows, block_cols);
      std::vector<cuda::TilePixel> tile(shape.slots());
      for (int slot = 0; slot < shape.slots(); ++slot) {
        tile[slot] = cuda::loadTilePixel(pixels, shape, slot);
        const int pixel = shape.pixelOfSlot(slot);
        if (pixel < 0) continue;
        const int found = shape.slotOfPixel(pixel);
        comparison.misplaced += found < 0 || found >= shape.slots() || shape.pixelOfSlot(found) != pixel;
      }
      const cuda::TileImage image{pixels.rows, pixels.cols, shape, tile.data(), scan.image.range.data()};
      for (int row = block_row; row < std::min(block_row + block_rows, pixels.rows); ++row) {
        for (int col = block_col; col < std::min(block_col + block_cols, pixels.cols); ++col) {
          if (!pixels.usable(row * pixels.cols + col)) continue;
          const Float3 whole = pixelNormal(pixels, row, col, params);
          const Float3 tiled = pixelNormal(image, row, col, params);
          comparison.normals += !isZero(whole);
          comparison.differing += std::memcmp(&whole, &tiled, sizeof(Float3)) != 0;
        }
      }
    }
  }
  return comparison;
}

// The tiles hold every pixel the windows reach, wrapping around the image's ends as the windows do: the
// kernel's 8 x 32 blocks, and on the narrower images odd shapes that end inside the image too; images
// narrower than one tile with its halo (some columns in it twice) and wider ones whose width no block
// shape divides.
TEST(NormalTile, NormalsFromTheTilesAreThoseFromTheWholeScanBitForBit) {
  for (const NormalMethod method : {NormalMethod::range_adaptive, NormalMethod::eigen, NormalMethod::cross_product}) {
    for (const int width : {2048, 1000, 24}) {
      Config config;
      config.normals.method = method;
      config.sensor.image_width = width;
      config.runtime.threads = 2;
      for (const auto& [block_rows, block_cols] : {std::pair{8, 32}, std::pair{3, 7}}) {
        if (width == 2048 && block_cols != 32) continue;  // the full image only as the kernel tiles it: time
        SCOPED_TRACE("method " + std::to_string(static_cast<int>(method)) + ", width " + std::to_string(width) +
                     ", blocks " + std::to_string(block_rows) + " x " + std::to_string(block_cols));
        const TileComparison comparison = compareTilesWithWholeScan(config, block_rows, block_cols);
        EXPECT_GT(comparison.normals, width == 2048 ? 10000u : 10u);
        EXPECT_EQ(comparison.differing, 0u);
        EXPECT_EQ(comparison.misplaced, 0u);
      }
    }
  }
}

// One column of a range image, as ground.hpp's Image.
struct ColumnImage {
  int rows;
  int cols = 1;
  std::vector<bool> occupied_rows{};
  std::vector<Float3> vertices{};
  mutable std::vector<PixelLabel> labels{};

  bool occupied(int pixel) const { return occupied_rows[pixel]; }
  Float3 vertex(int pixel) const { return vertices[pixel]; }
  void setLabel(int pixel, PixelLabel label) const { labels[pixel] = label; }

  std::vector<uint32_t> bits() const {
    std::vector<uint32_t> words((rows + 31) / 32, 0u);
    for (int row = 0; row < rows; ++row) words[row / 32] |= occupied_rows[row] ? 1u << (row % 32) : 0u;
    return words;
  }
};

TEST(ColumnBits, NameTheNearestOccupiedRowsAcrossWords) {
  ColumnImage column{80};
  column.occupied_rows.assign(80, false);
  for (const int row : {0, 31, 32, 63, 79}) column.occupied_rows[row] = true;
  const std::vector<uint32_t> words = column.bits();
  const ColumnBits bits{words.data(), 1, static_cast<int>(words.size())};
  EXPECT_EQ(occupiedRowAbove(bits, 0), -1);
  EXPECT_EQ(occupiedRowBelow(bits, 0), 31);
  EXPECT_EQ(occupiedRowAbove(bits, 31), 0);
  EXPECT_EQ(occupiedRowBelow(bits, 31), 32);
  EXPECT_EQ(occupiedRowAbove(bits, 32), 31);
  EXPECT_EQ(occupiedRowBelow(bits, 32), 63);
  EXPECT_EQ(occupiedRowAbove(bits, 50), 32);  // an empty row names its neighbours too
  EXPECT_EQ(occupiedRowBelow(bits, 63), 79);
  EXPECT_EQ(occupiedRowAbove(bits, 79), 63);
  EXPECT_EQ(occupiedRowBelow(bits, 79), -1);
  EXPECT_TRUE(bits.occupied(63));
  EXPECT_FALSE(bits.occupied(64));
  const std::vector<uint32_t> none(3, 0u);
  const ColumnBits empty{none.data(), 1, 3};
  EXPECT_EQ(occupiedRowAbove(empty, 70), -1);
  EXPECT_EQ(occupiedRowBelow(empty, 5), -1);
}

// The GPU labels each pixel from its column's bits (pixelGroundLabel()); the CPU walks the column
// (segmentColumn()). Random columns of road and obstacles, of every fill, as tall as one word, less, and
// more: the same labels, the unoccupied pixels left alone.
TEST(ColumnBits, PerPixelGroundLabelsAreThoseOfTheColumnWalk) {
  GroundConfig gated;  // the road within 10 m ground whatever its slope (ground.min_range)
  gated.min_range = 10.0;
  std::mt19937 random(11);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  size_t ground = 0;
  size_t nonground = 0;
  for (const GroundConfig& ground_config : {GroundConfig(), gated}) {
    const GroundBand band = GroundBand::fromConfig(ground_config);
    for (const int rows : {1, 2, 31, 32, 33, 64, 80, 130}) {
      for (const float fill : {0.0f, 0.1f, 0.5f, 0.9f, 1.0f}) {
        for (int trial = 0; trial < 20; ++trial) {
          ColumnImage column{rows};
          for (int row = 0; row < rows; ++row) {
            column.occupied_rows.push_back(unit(random) < fill);
            // Rings reach the road farther out the higher they are; a fifth of the points lie on obstacles.
            const float distance = 4.0f + 0.5f * static_cast<float>(rows - row);
            const float height = unit(random) < 0.2f ? 2.0f * unit(random) - 1.0f : 0.03f * unit(random);
            column.vertices.push_back({distance, 0.0f, static_cast<float>(-GroundConfig().sensor_height) + height});
          }
          column.labels.assign(rows, PixelLabel::empty);
          ColumnImage walked = column;
          segmentColumn(walked, 0, band);
          const std::vector<uint32_t> words = column.bits();
          const ColumnBits bits{words.data(), 1, static_cast<int>(words.size())};
          for (int row = 0; row < rows; ++row) {
            if (bits.occupied(row)) column.setLabel(row, pixelGroundLabel(column, bits, row, 0, band));
          }
          ASSERT_EQ(column.labels, walked.labels) << rows << " rows, fill " << fill << ", trial " << trial;
          ground += std::count(walked.labels.begin(), walked.labels.end(), PixelLabel::ground);
          nonground += std::count(walked.labels.begin(), walked.labels.end(), PixelLabel::nonground);
        }
      }
    }
  }
  EXPECT_GT(ground, 1000u);
  EXPECT_GT(nonground, 1000u);
}

// The pixels forEachSplatPixel() offers a point at (row, col), `range` away, with a disc of `radius`.
std::set<std::pair<int, int>> splatPixels(const SphericalProjection& projection, int row, int col, float range,
                                          float radius = 1.0f) {
  std::set<std::pair<int, int>> pixels;
  forEachSplatPixel(projection, row, col, range, radius,
                    [&](int pixel) { pixels.insert({pixel / projection.cols, pixel % projection.cols}); });
  return pixels;
}

// A disc spans as many whole rows and columns either side as its angle covers: across the azimuth seam,
// cut at the image's edge, at most 4 columns and 2 rows however close (a point at the sensor too), and a
// far point, or one without a disc, its pixel alone.
TEST(MapRenderRules, ADiscCoversItsPixelsAcrossTheSeamUpToTheCap) {
  SphericalProjection projection;
  projection.rows = 10;
  projection.cols = 100;      // 0.0628 rad a column
  projection.fov_span = 0.5f;  // 0.05 rad a row
  // 0.13 rad: 2 columns and 2 rows either side; at the top-left corner, rows 0-2 and columns 98-2.
  std::set<std::pair<int, int>> expected;
  for (int row = 0; row <= 2; ++row) {
    for (const int col : {98, 99, 0, 1, 2}) expected.insert({row, col});
  }
  EXPECT_EQ(splatPixels(projection, 0, 0, 1.0f / 0.13f), expected);
  // 2 rad, capped: 4 columns and 2 rows either side.
  expected.clear();
  for (int row = 3; row <= 7; ++row) {
    for (int col = 46; col <= 54; ++col) expected.insert({row, col});
  }
  EXPECT_EQ(splatPixels(projection, 5, 50, 0.5f), expected);
  EXPECT_EQ(splatPixels(projection, 5, 50, 0.0f), expected);  // at the sensor: an infinite angle
  const std::set<std::pair<int, int>> alone{{9, 99}};
  EXPECT_EQ(splatPixels(projection, 9, 99, 100.0f), alone);
  EXPECT_EQ(splatPixels(projection, 9, 99, 0.0f, 0.0f), alone);  // no disc: 0 / 0
}

// A map point is ground in the band when its normal is near vertical (either way) or unknown; the
// height above the band's floor ranks a cell's ground points.
TEST(MapRenderRules, GroundIsTheBandWhereNormalsAreNearVertical) {
  const MapRendering rendering{0.2f, -2.0f, -1.5f, 0.3f};
  const Float3 road{5.0f, 1.0f, -1.8f};
  EXPECT_TRUE(isMapGround(road, Float3{0.0f, 0.0f, 0.0f}, rendering));
  EXPECT_TRUE(isMapGround(road, Float3{0.0f, 0.3f, -0.95f}, rendering));
  EXPECT_FALSE(isMapGround(road, Float3{0.6f, 0.0f, 0.8f}, rendering));  // a kerb's face
  EXPECT_FALSE(isMapGround(Float3{5.0f, 1.0f, -1.4f}, Float3{0.0f, 0.0f, 1.0f}, rendering));
  EXPECT_FALSE(isMapGround(Float3{5.0f, 1.0f, -2.1f}, Float3{0.0f, 0.0f, 1.0f}, rendering));
  EXPECT_NEAR(mapGroundAge(road, rendering), 0.2f, 1e-6f);
}

}  // namespace
}  // namespace elo
