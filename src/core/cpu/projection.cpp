// Sec. III-B.1: spherical projection of the scan into an index range image, closest point per pixel.
#include <cmath>

#include "core/cpu/parallel.hpp"
#include "core/cpu/stages.hpp"

namespace elo::cpu {

namespace {

struct ElevationCorrection {
  bool active = false;
  float cos_angle = 1.0f;
  float sin_angle = 0.0f;

  explicit ElevationCorrection(double degrees)
      : active(degrees != 0.0),
        cos_angle(static_cast<float>(std::cos(degrees * M_PI / 180.0))),
        sin_angle(static_cast<float>(std::sin(degrees * M_PI / 180.0))) {}

  Vec3f apply(const Vec3f& p) const { return active ? correctElevation(p, cos_angle, sin_angle) : p; }
};

}  // namespace

size_t projectCloud(const PointCloud& cloud, const SensorConfig& sensor, const SphericalProjection& projection,
                    const std::vector<int>& ring_rows, float stamp, ClosestWins& winners, ScanImage& scan) {
  const ElevationCorrection correction(sensor.elevation_correction_deg);
  const bool use_ring = !ring_rows.empty() && cloud.ring.size() == cloud.points.size();
  winners.reset();
  parallelFor(cloud.points.size(), [&](size_t i) {
    if (!cloud.points[i].allFinite()) return;
    const Vec3f p = correction.apply(cloud.points[i]);
    int row = 0;
    int col = 0;
    if (!projection.pixelOf(p, row, col)) return;
    if (use_ring) {
      // The driver knows the beam: its row is exact where the elevation of a noisy point is not.
      const uint16_t ring = cloud.ring[i];
      if (ring >= ring_rows.size()) return;
      row = ring_rows[ring];
      if (row < 0 || row >= projection.rows) return;
    }
    winners.offer(static_cast<size_t>(row) * projection.cols + col, p.norm(), static_cast<uint32_t>(i));
  });

  SphericalImage& image = scan.image;
  std::atomic<size_t> occupied{0};
  parallelFor(image.pixelCount(), [&](size_t pixel) {
    image.normal[pixel].setZero();
    if (!winners.occupied(pixel)) {
      image.range[pixel] = 0.0f;
      scan.point_index[pixel] = -1;
      scan.label[pixel] = PixelLabel::empty;
      return;
    }
    const uint32_t index = winners.winner(pixel);
    const Vec3f p = correction.apply(cloud.points[index]);
    image.vertex[pixel] = p;
    image.range[pixel] = p.norm();
    image.stamp[pixel] = stamp;
    scan.point_index[pixel] = static_cast<int32_t>(index);
    scan.label[pixel] = PixelLabel::nonground;
    occupied.fetch_add(1, std::memory_order_relaxed);
  });
  return occupied.load();
}

}  // namespace elo::cpu
