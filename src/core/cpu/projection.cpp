// Sec. III-B.1: spherical projection of the scan into an index range image, closest point per pixel, each
// point deskewed first. The per-point math is shared with the CUDA backend (scan_projection.hpp).
#include "core/common/eigen_interop.hpp"
#include "core/common/scan_projection.hpp"
#include "core/cpu/parallel.hpp"
#include "core/cpu/stages.hpp"

namespace elo::cpu {

size_t projectCloud(const PointCloud& cloud, const SensorConfig& sensor, const SphericalProjection& projection,
                    const std::vector<int>& ring_rows, const SweepDeskew& deskew, float stamp, ClosestWins& winners,
                    std::vector<ScanPoint>& placed, ScanImage& scan) {
  const ElevationCorrection correction = ElevationCorrection::fromConfig(sensor);
  const bool use_ring = !ring_rows.empty() && cloud.ring.size() == cloud.points.size();
  const auto place = [&](size_t i, ScanPoint& point) {
    const int ring = use_ring ? cloud.ring[i] : kNoRing;
    return scanPointPixel(projection, correction, deskew, static_cast<int>(i), toFloat3(cloud.points[i]), ring,
                          ring_rows.data(), static_cast<int>(ring_rows.size()), point);
  };
  // Every placed point is kept, so that the winners need not be corrected and deskewed again.
  placed.resize(cloud.points.size());
  winners.setSingleWriter(runsAlone());
  parallelFor(cloud.points.size(), [&](size_t i) {
    ScanPoint& point = placed[i];
    if (place(i, point)) winners.offer(point.pixel, norm(point.vertex), static_cast<uint32_t>(i));
  });

  // Each pixel takes its winner (which empties the pixel for the next scan). The winner's range is the
  // one its key holds: the norm of the same vertex.
  SphericalImage& image = scan.image;
  return deterministicSum<size_t>(image.pixelCount(), [&](size_t begin, size_t end, size_t& occupied) {
    for (size_t pixel = begin; pixel < end; ++pixel) {
      const ClosestKey key = winners.take(pixel);
      image.normal[pixel].setZero();
      if (key == kNoClosestKey) {
        image.range[pixel] = 0.0f;
        scan.point_index[pixel] = -1;
        scan.label[pixel] = PixelLabel::empty;
        continue;
      }
      const uint32_t index = closestWinsSource(key);
      const ScanPoint& point = placed[index];
      image.vertex[pixel] = toVec3f(point.vertex);
      image.range[pixel] = closestWinsRange(key);
      image.stamp[pixel] = stamp;
      scan.measured[pixel] = toVec3f(point.measured);
      scan.time[pixel] = point.time;
      scan.point_index[pixel] = static_cast<int32_t>(index);
      scan.label[pixel] = PixelLabel::nonground;
      ++occupied;
    }
  });
}

}  // namespace elo::cpu
