#include "elo/map/point_map.hpp"

#include <tbb/parallel_for.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <limits>

namespace elo {
namespace {

// A normal fit needs this many points within the radius, the point itself included.
constexpr int kMinNormalNeighbours = 5;
// lambda_min / (lambda_1 + lambda_2 + lambda_3) above this is no plane (normals.max_curvature is 0.1 for
// the scan's windows; a map's neighbourhood is a disc of half a metre, so corners weigh alike).
constexpr double kMaxPlaneCurvature = 0.1;

// Voxels of `size` keyed by their integer coordinates, for the neighbour search of the normal fit.
class VoxelIndex {
 public:
  VoxelIndex(const std::vector<Vec3f>& points, double size) : points_(points), size_(size) {
    for (size_t i = 0; i < points.size(); ++i) cells_[keyOf(cellOf(points[i]))].push_back(static_cast<int32_t>(i));
  }

  // Calls visit(neighbour) for every point within `radius` (= the voxel size) of `center`.
  template <typename Visit>
  void forEachNear(const Vec3f& center, const Visit& visit) const {
    const Eigen::Vector3i cell = cellOf(center);
    const float radius_squared = static_cast<float>(size_ * size_);
    for (int dz = -1; dz <= 1; ++dz) {
      for (int dy = -1; dy <= 1; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) {
          const auto found = cells_.find(keyOf(cell + Eigen::Vector3i(dx, dy, dz)));
          if (found == cells_.end()) continue;
          for (int32_t other : found->second) {
            if ((points_[other] - center).squaredNorm() <= radius_squared) visit(other);
          }
        }
      }
    }
  }

 private:
  Eigen::Vector3i cellOf(const Vec3f& point) const {
    return (point.cast<double>() / size_).array().floor().cast<int>();
  }
  static uint64_t keyOf(const Eigen::Vector3i& cell) {
    // 21 bits per axis: +-1e6 voxels, 500 km at half a metre.
    const auto bits = [](int value) { return static_cast<uint64_t>(value + (1 << 20)) & 0x1FFFFF; };
    return bits(cell.x()) | (bits(cell.y()) << 21) | (bits(cell.z()) << 42);
  }

  const std::vector<Vec3f>& points_;
  double size_;
  std::unordered_map<uint64_t, std::vector<int32_t>> cells_;
};

// The plane normal of the neighbours of `center` (relative to it, so float precision holds far from the
// map's origin); zero when they are too few or not planar.
template <typename Index>
Vec3f fitNormal(const Index& index, const std::vector<Vec3f>& points, const Vec3f& center) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  Eigen::Matrix3d products = Eigen::Matrix3d::Zero();
  int count = 0;
  index.forEachNear(center, [&](int32_t other) {
    const Eigen::Vector3d offset = (points[other] - center).cast<double>();
    sum += offset;
    products += offset * offset.transpose();
    ++count;
  });
  if (count < kMinNormalNeighbours) return Vec3f::Zero();
  const Eigen::Vector3d mean = sum / count;
  const Eigen::Matrix3d covariance = products / count - mean * mean.transpose();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(covariance);
  const double total = eigen.eigenvalues().sum();
  if (!(total > 0.0) || eigen.eigenvalues()(0) / total > kMaxPlaneCurvature) return Vec3f::Zero();
  return eigen.eigenvectors().col(0).normalized().cast<float>();
}

bool isUnit(const Vec3f& normal) { return std::abs(normal.squaredNorm() - 1.0f) < 1e-3f; }

}  // namespace

void estimateMapNormals(MapCloud& map, double radius) {
  const VoxelIndex index(map.points, radius);
  map.normals.assign(map.points.size(), Vec3f::Zero());
  tbb::parallel_for(size_t{0}, map.points.size(),
                    [&](size_t i) { map.normals[i] = fitNormal(index, map.points, map.points[i]); });
}

MapPreparation prepareMap(MapCloud& map, double normal_radius) {
  MapPreparation preparation;
  const bool had_normals = map.normals.size() == map.points.size();
  const bool had_intensity = map.intensity.size() == map.points.size();
  size_t kept = 0;
  for (size_t i = 0; i < map.points.size(); ++i) {
    if (!map.points[i].allFinite()) {
      ++preparation.non_finite_dropped;
      continue;
    }
    map.points[kept] = map.points[i];
    if (had_intensity) map.intensity[kept] = map.intensity[i];
    if (had_normals) {
      Vec3f normal = map.normals[i];
      if (!normal.isZero() && !(normal.allFinite() && isUnit(normal))) {
        ++preparation.bad_normals;
        normal.setZero();
      }
      map.normals[kept] = normal;
    }
    ++kept;
  }
  map.points.resize(kept);
  if (had_intensity) map.intensity.resize(kept);
  if (!had_intensity) map.intensity.clear();
  if (had_normals) {
    map.normals.resize(kept);
    return preparation;
  }
  estimateMapNormals(map, normal_radius);
  preparation.estimated = true;
  for (const Vec3f& normal : map.normals) preparation.normals_estimated += normal.isZero() ? 0 : 1;
  return preparation;
}

MapTiles::MapTiles(const MapCloud& map, double tile_size) : map_(map), tile_size_(tile_size) {
  if (map.points.empty()) return;
  lower_ = Eigen::Vector2d::Constant(std::numeric_limits<double>::infinity());
  upper_ = -lower_;
  for (size_t i = 0; i < map.points.size(); ++i) {
    const Eigen::Vector2d xy = map.points[i].head<2>().cast<double>();
    lower_ = lower_.cwiseMin(xy);
    upper_ = upper_.cwiseMax(xy);
    tiles_[key(cellOf(map.points[i]))].push_back(static_cast<int32_t>(i));
  }
}

uint64_t MapTiles::key(const Cell& cell) {
  return (static_cast<uint64_t>(cell.col) << 32) ^ (static_cast<uint64_t>(cell.row) & 0xFFFFFFFFu);
}

MapTiles::Cell MapTiles::cellOf(const Vec3f& point) const {
  return {static_cast<int64_t>(std::floor(point.x() / tile_size_)),
          static_cast<int64_t>(std::floor(point.y() / tile_size_))};
}

const std::vector<int32_t>* MapTiles::pointsIn(const Cell& cell) const {
  const auto found = tiles_.find(key(cell));
  return found == tiles_.end() ? nullptr : &found->second;
}

void MapTiles::pointsNear(const Eigen::Vector3d& center, double radius, std::vector<int32_t>& out) const {
  const int64_t first_col = static_cast<int64_t>(std::floor((center.x() - radius) / tile_size_));
  const int64_t last_col = static_cast<int64_t>(std::floor((center.x() + radius) / tile_size_));
  const int64_t first_row = static_cast<int64_t>(std::floor((center.y() - radius) / tile_size_));
  const int64_t last_row = static_cast<int64_t>(std::floor((center.y() + radius) / tile_size_));
  const double radius_squared = radius * radius;
  for (int64_t row = first_row; row <= last_row; ++row) {
    for (int64_t col = first_col; col <= last_col; ++col) {
      const std::vector<int32_t>* points = pointsIn({col, row});
      if (points == nullptr) continue;
      // A tile wholly inside the disc needs no test per point.
      const double far_x = std::max(std::abs(col * tile_size_ - center.x()), std::abs((col + 1) * tile_size_ - center.x()));
      const double far_y = std::max(std::abs(row * tile_size_ - center.y()), std::abs((row + 1) * tile_size_ - center.y()));
      if (far_x * far_x + far_y * far_y <= radius_squared) {
        out.insert(out.end(), points->begin(), points->end());
        continue;
      }
      for (int32_t point : *points) {
        const Eigen::Vector2d offset = map_.points[point].head<2>().cast<double>() - center.head<2>();
        if (offset.squaredNorm() <= radius_squared) out.push_back(point);
      }
    }
  }
}

}  // namespace elo
