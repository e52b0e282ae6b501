// Sec. III-B.1: spherical projection of the scan into an index range image, closest point per pixel. The
// per-point math is shared with the CUDA backend (scan_projection.hpp).
#include "core/common/eigen_interop.hpp"
#include "core/common/scan_projection.hpp"
#include "core/cpu/parallel.hpp"
#include "core/cpu/stages.hpp"

namespace elo::cpu {

size_t projectCloud(const PointCloud& cloud, const SensorConfig& sensor, const SphericalProjection& projection,
                    const std::vector<int>& ring_rows, float stamp, ClosestWins& winners, ScanImage& scan) {
  const ElevationCorrection correction = ElevationCorrection::fromConfig(sensor);
  const bool use_ring = !ring_rows.empty() && cloud.ring.size() == cloud.points.size();
  winners.reset();
  parallelFor(cloud.points.size(), [&](size_t i) {
    Float3 corrected;
    int pixel = 0;
    const int ring = use_ring ? cloud.ring[i] : kNoRing;
    if (!scanPointPixel(projection, correction, toFloat3(cloud.points[i]), ring, ring_rows.data(),
                        static_cast<int>(ring_rows.size()), corrected, pixel)) {
      return;
    }
    winners.offer(pixel, norm(corrected), static_cast<uint32_t>(i));
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
    const Float3 p = correction.apply(toFloat3(cloud.points[index]));
    image.vertex[pixel] = toVec3f(p);
    image.range[pixel] = norm(p);
    image.stamp[pixel] = stamp;
    scan.point_index[pixel] = static_cast<int32_t>(index);
    scan.label[pixel] = PixelLabel::nonground;
    occupied.fetch_add(1, std::memory_order_relaxed);
  });
  return occupied.load();
}

}  // namespace elo::cpu
