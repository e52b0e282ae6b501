// Mean map entropy: the spread of a noisy plane, and a sharper map for the right poses than for wrong ones.
#include <gtest/gtest.h>

#include <random>

#include "elo/eval/map_entropy.hpp"

namespace elo {
namespace {

// A scan of three walls of a room seen from its middle: a floor-to-ceiling grid on each, every point
// offset along its wall's normal by Gaussian noise of `noise` metres.
std::vector<Eigen::Vector3f> roomScan(float noise, unsigned seed) {
  std::mt19937 random(seed);
  std::normal_distribution<float> offset(0.0f, noise);
  std::vector<Eigen::Vector3f> points;
  for (float a = -6.0f; a <= 6.0f; a += 0.02f) {
    for (float z = -1.5f; z <= 1.5f; z += 0.02f) {
      points.emplace_back(8.0f + offset(random), a, z);   // the wall ahead
      points.emplace_back(a, 7.0f + offset(random), z);   // on the left
      points.emplace_back(a, -7.0f + offset(random), z);  // on the right
    }
  }
  return points;
}

TEST(MapEntropy, ThePlaneDeviationOfANoisyWallIsItsNoise) {
  std::vector<Eigen::Vector3f> map;
  addScanToMap(roomScan(0.01f, 1), Eigen::Isometry3d::Identity(), MapEntropyOptions{}, map);
  const MapEntropy entropy = mapEntropy(map, MapEntropyOptions{});
  EXPECT_NEAR(entropy.mean_plane_deviation_m, 0.01, 0.001);
  EXPECT_GT(entropy.scored_points, 100u);
}

TEST(MapEntropy, TheTruePosesGiveTheSharperMap) {
  // The sensor moved 0.5 m forward between two scans of the room.
  Eigen::Isometry3d second = Eigen::Isometry3d::Identity();
  second.translation() << 0.5, 0.0, 0.0;
  std::vector<Eigen::Vector3f> second_scan = roomScan(0.01f, 2);
  for (Eigen::Vector3f& point : second_scan) point = (second.inverse().cast<float>() * point).eval();
  const auto entropyWith = [&](const Eigen::Isometry3d& estimate) {
    std::vector<Eigen::Vector3f> map;
    addScanToMap(roomScan(0.01f, 1), Eigen::Isometry3d::Identity(), MapEntropyOptions{}, map);
    addScanToMap(second_scan, estimate, MapEntropyOptions{}, map);
    return mapEntropy(map, MapEntropyOptions{});
  };
  Eigen::Isometry3d off_by_5cm = second;
  off_by_5cm.translation().x() += 0.05;
  const Eigen::Isometry3d turned = second * Eigen::AngleAxisd(0.01, Eigen::Vector3d::UnitZ());
  const MapEntropy right = entropyWith(second);
  EXPECT_LT(right.mean_entropy, entropyWith(off_by_5cm).mean_entropy);
  EXPECT_LT(right.mean_entropy, entropyWith(turned).mean_entropy);
  EXPECT_NEAR(right.mean_plane_deviation_m, 0.01, 0.001);
  EXPECT_GT(entropyWith(off_by_5cm).mean_plane_deviation_m, 0.015) << "the wall ahead splits in two 5 cm apart";
}

TEST(MapEntropy, PointsOutsideTheRangesStayOutOfTheMap) {
  const std::vector<Eigen::Vector3f> scan = {{1.0f, 0.0f, 0.0f}, {10.0f, 0.0f, 0.0f}, {0.0f, 40.0f, 0.0f}};
  std::vector<Eigen::Vector3f> map;
  MapEntropyOptions options;
  options.point_stride = 1;
  addScanToMap(scan, Eigen::Isometry3d::Identity(), options, map);
  ASSERT_EQ(map.size(), 1u);
  EXPECT_EQ(map[0], scan[1]);
}

TEST(MapEntropy, AMapTooSparseToScoreIsAnError) {
  EXPECT_THROW(mapEntropy({}, MapEntropyOptions{}), std::invalid_argument);
  EXPECT_THROW(mapEntropy({{10.0f, 0.0f, 0.0f}, {10.0f, 1.0f, 0.0f}}, MapEntropyOptions{}), std::invalid_argument);
}

}  // namespace
}  // namespace elo
