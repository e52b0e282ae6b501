// Sec. III-C.2: the bird's-eye-view map of ground points, and the normals of the BEV model fitted to
// the model points nearest an associated cell.
#include <algorithm>
#include <array>

#include "core/cpu/plane_fit.hpp"
#include "core/cpu/stages.hpp"

namespace elo::cpu {

namespace {

// Below this middle eigenvalue (1 cm spread across the line) the points lie on one scan ring and the
// plane through them could turn about it freely.
constexpr double kMinCrossSpread = 1e-4;
// Upper bound of bev.normal_neighbours honoured by the fixed-size buffers of the fit.
constexpr int kMaxNormalNeighbours = 32;

}  // namespace

void keepCloserGroundPoint(BevImage& map, int32_t cell, const Vec3f& vertex, float stamp) {
  const float range = vertex.norm();
  if (!map.occupied(cell)) {
    map.occupied_cells.push_back(cell);
  } else if (map.range[cell] <= range) {
    return;
  }
  map.vertex[cell] = vertex;
  map.range[cell] = range;
  map.stamp[cell] = stamp;
}

void buildGroundMap(const ScanImage& scan, const BevProjection& projection, BevImage& ground) {
  ground.clear();
  const SphericalImage& image = scan.image;
  for (size_t pixel = 0; pixel < image.pixelCount(); ++pixel) {
    if (scan.label[pixel] != PixelLabel::ground) continue;
    int row = 0;
    int col = 0;
    if (!projection.cellOf(image.vertex[pixel], row, col)) continue;
    keepCloserGroundPoint(ground, row * projection.cols + col, image.vertex[pixel], image.stamp[pixel]);
  }
}

void GroundNormalCache::resize(size_t cells) {
  normals_.assign(cells, Vec3f::Zero());
  states_ = std::make_unique<std::atomic<uint8_t>[]>(cells);
  for (size_t i = 0; i < cells; ++i) states_[i].store(unknown, std::memory_order_relaxed);
}

void GroundNormalCache::invalidate(const BevImage& model) {
  for (int32_t cell : model.occupied_cells) states_[cell].store(unknown, std::memory_order_relaxed);
}

Vec3f GroundNormalCache::normal(const BevImage& model, const BevProjection& projection, const BevConfig& config,
                                int32_t cell) {
  if (states_[cell].load(std::memory_order_acquire) == fitted) return normals_[cell];

  // The `normal_neighbours` model points of the patch nearest to the cell's vertex, kept sorted.
  const Vec3f& centre = model.vertex[cell];
  const int row = cell / projection.cols;
  const int col = cell % projection.cols;
  const int radius = config.normal_patch_radius;
  const int wanted = std::min(config.normal_neighbours, kMaxNormalNeighbours);
  std::array<float, kMaxNormalNeighbours> distances;
  std::array<Vec3f, kMaxNormalNeighbours> points;
  int used = 0;
  for (int r = std::max(0, row - radius); r <= std::min(projection.rows - 1, row + radius); ++r) {
    for (int c = std::max(0, col - radius); c <= std::min(projection.cols - 1, col + radius); ++c) {
      const int32_t other = r * projection.cols + c;
      if (!model.occupied(other)) continue;
      const float distance = (model.vertex[other] - centre).squaredNorm();
      if (used == wanted && distance >= distances[used - 1]) continue;
      int slot = used < wanted ? used++ : used - 1;
      for (; slot > 0 && distances[slot - 1] > distance; --slot) {
        distances[slot] = distances[slot - 1];
        points[slot] = points[slot - 1];
      }
      distances[slot] = distance;
      points[slot] = model.vertex[other];
    }
  }

  Vec3f normal = Vec3f::Zero();
  const PlaneFit fit = fitPlane(points.data(), used, centre);
  if (fit.valid && fit.middle_eigenvalue >= kMinCrossSpread) {
    normal = fit.normal.z() < 0.0f ? Vec3f(-fit.normal) : fit.normal;  // ground normals point up
  }
  uint8_t expected = unknown;
  if (states_[cell].compare_exchange_strong(expected, fitting, std::memory_order_acq_rel)) {
    normals_[cell] = normal;
    states_[cell].store(fitted, std::memory_order_release);
  }
  return normal;
}

}  // namespace elo::cpu
