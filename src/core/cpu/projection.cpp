// Sec. III-B.1: spherical projection of the scan into an index range image, closest point per pixel, each
// point deskewed first. The per-point math is shared with the CUDA backend (scan_projection.hpp).
#include "core/common/eigen_interop.hpp"
#include "core/common/scan_projection.hpp"
#include "core/cpu/parallel.hpp"
#include "core/cpu/stages.hpp"

namespace elo::cpu {

size_t projectCloud(const PointCloud& cloud, const SensorConfig& sensor, const SphericalProjection& projection,
                    const std::vector<int>& ring_rows, const SweepDeskew& deskew, float stamp, ClosestWins& winners,
                    ScanImage& scan) {
  const ElevationCorrection correction = ElevationCorrection::fromConfig(sensor);
  const bool use_ring = !ring_rows.empty() && cloud.ring.size() == cloud.points.size();
  const auto place = [&](size_t i, ScanPoint& point) {
    const int ring = use_ring ? cloud.ring[i] : kNoRing;
    return scanPointPixel(projection, correction, deskew, static_cast<int>(i), toFloat3(cloud.points[i]), ring,
                          ring_rows.data(), static_cast<int>(ring_rows.size()), point);
  };
  winners.reset();
  parallelFor(cloud.points.size(), [&](size_t i) {
    ScanPoint point;
    if (place(i, point)) winners.offer(point.pixel, norm(point.vertex), static_cast<uint32_t>(i));
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
    ScanPoint point;
    scanPointVertex(correction, deskew, static_cast<int>(index), toFloat3(cloud.points[index]), point);
    image.vertex[pixel] = toVec3f(point.vertex);
    image.range[pixel] = norm(point.vertex);
    image.stamp[pixel] = stamp;
    scan.measured[pixel] = toVec3f(point.measured);
    scan.time[pixel] = point.time;
    scan.point_index[pixel] = static_cast<int32_t>(index);
    scan.label[pixel] = PixelLabel::nonground;
    occupied.fetch_add(1, std::memory_order_relaxed);
  });
  return occupied.load();
}

}  // namespace elo::cpu
