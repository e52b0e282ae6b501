// Sec. III-C.2: the bird's-eye-view map of ground points, and the normals of the BEV model fitted to
// the model points nearest an associated cell.
#include <algorithm>
#include <array>
#include <cmath>

#include "core/cpu/plane_fit.hpp"
#include "core/cpu/stages.hpp"

namespace elo::cpu {

namespace {

// Below this smallest eigenvalue of their horizontal spread (1 cm across the line) the points lie on one
// scan ring and the plane through them could turn about it freely.
constexpr float kMinCrossSpread = 1e-4f;

// The upward normal of the plane z = a x + b y + c fitted to `points` by least squares (a ground patch
// is never vertical, so this 2x2 solve replaces an eigen-decomposition), or zero when the points are
// (nearly) collinear in x-y.
Vec3f groundPlaneNormal(const Vec3f* points, int count, const Vec3f& origin) {
  if (count < 3) return Vec3f::Zero();
  PointMoments moments;
  for (int i = 0; i < count; ++i) moments.add(points[i] - origin);
  const Eigen::Matrix3f covariance = moments.covariance();
  const float cxx = covariance(0, 0);
  const float cxy = covariance(0, 1);
  const float cyy = covariance(1, 1);
  const float determinant = cxx * cyy - cxy * cxy;
  const float half_trace = 0.5f * (cxx + cyy);
  const float smallest_spread = half_trace - std::sqrt(std::max(half_trace * half_trace - determinant, 0.0f));
  if (!(smallest_spread >= kMinCrossSpread)) return Vec3f::Zero();
  const float a = (cyy * covariance(0, 2) - cxy * covariance(1, 2)) / determinant;
  const float b = (cxx * covariance(1, 2) - cxy * covariance(0, 2)) / determinant;
  return Vec3f(-a, -b, 1.0f).normalized();
}
// Upper bound of bev.normal_neighbours honoured by the fixed-size buffers of the fit.
constexpr int kMaxNormalNeighbours = 32;

}  // namespace

void buildGroundMap(const ScanImage& scan, const BevProjection& projection, BevImage& ground) {
  ground.clear();
  const SphericalImage& image = scan.image;
  for (size_t pixel = 0; pixel < image.pixelCount(); ++pixel) {
    if (scan.label[pixel] != PixelLabel::ground) continue;
    int row = 0;
    int col = 0;
    if (!projection.cellOf(image.vertex[pixel], row, col)) continue;
    ground.keepCloser(row * projection.cols + col, image.vertex[pixel], image.stamp[pixel]);
  }
}

namespace {

// Calls `visit(point)` for every point of `map` in the cells at Chebyshev distance `ring` from (row, col).
template <typename Visit>
void forEachPointOnRing(const BevImage& map, const BevProjection& projection, int row, int col, int ring,
                        const Visit& visit) {
  for (int r = std::max(0, row - ring); r <= std::min(projection.rows - 1, row + ring); ++r) {
    const bool edge_row = r == row - ring || r == row + ring;
    const int step = edge_row || ring == 0 ? 1 : 2 * ring;  // inner rows: only the ring's two ends
    for (int c = col - ring; c <= col + ring; c += step) {
      if (c < 0 || c >= projection.cols) continue;
      const int32_t point = map.point_of_cell[r * projection.cols + c];
      if (point >= 0) visit(point);
    }
  }
}

}  // namespace

int32_t nearestGroundPoint(const BevImage& map, const BevProjection& projection, const Vec3f& point, int row, int col,
                           int radius) {
  for (int ring = 0; ring <= radius; ++ring) {
    int32_t best = -1;
    float best_distance = INFINITY;
    forEachPointOnRing(map, projection, row, col, ring, [&](int32_t candidate) {
      const float distance = (map.vertex[candidate] - point).squaredNorm();
      if (distance < best_distance) {
        best_distance = distance;
        best = candidate;
      }
    });
    if (best >= 0) return best;
  }
  return -1;
}

void GroundNormalCache::reset(size_t points) {
  if (points > capacity_) {
    capacity_ = points + points / 2;
    normals_.resize(capacity_);
    states_ = std::make_unique<std::atomic<uint8_t>[]>(capacity_);
  }
  for (size_t i = 0; i < points; ++i) states_[i].store(unknown, std::memory_order_relaxed);
}

Vec3f GroundNormalCache::normal(const BevImage& model, const BevProjection& projection, const BevConfig& config,
                                int32_t point) {
  if (states_[point].load(std::memory_order_acquire) == fitted) return normals_[point];

  // The `normal_neighbours` model points of the patch nearest to the point, kept sorted. Rings of cells
  // are searched outwards; once the farthest kept point is closer than any point of the next ring can be
  // (ring - 1 cells, as the centre may lie at the edge of its own cell), the rest cannot change the result.
  const Vec3f& centre = model.vertex[point];
  const int row = model.cell[point] / projection.cols;
  const int col = model.cell[point] % projection.cols;
  const int wanted = std::min(config.normal_neighbours, kMaxNormalNeighbours);
  std::array<float, kMaxNormalNeighbours> distances;
  std::array<Vec3f, kMaxNormalNeighbours> points;
  int used = 0;
  for (int ring = 0; ring <= config.normal_patch_radius; ++ring) {
    const float ring_distance = static_cast<float>(std::max(ring - 1, 0)) * projection.cell_size;
    if (used == wanted && distances[used - 1] <= ring_distance * ring_distance) break;
    forEachPointOnRing(model, projection, row, col, ring, [&](int32_t other) {
      const float distance = (model.vertex[other] - centre).squaredNorm();
      if (used == wanted && distance >= distances[used - 1]) return;
      int slot = used < wanted ? used++ : used - 1;
      for (; slot > 0 && distances[slot - 1] > distance; --slot) {
        distances[slot] = distances[slot - 1];
        points[slot] = points[slot - 1];
      }
      distances[slot] = distance;
      points[slot] = model.vertex[other];
    });
  }

  const Vec3f normal = groundPlaneNormal(points.data(), used, centre);
  uint8_t expected = unknown;
  if (states_[point].compare_exchange_strong(expected, fitting, std::memory_order_acq_rel)) {
    normals_[point] = normal;
    states_[point].store(fitted, std::memory_order_release);
  }
  return normal;
}

}  // namespace elo::cpu
