// Sec. III-B.1: spherical projection of the scan into an index range image, closest point per pixel, each
// point deskewed first. The per-point math is shared with the CUDA backend (scan_projection.hpp).
#include <type_traits>

#include "core/common/eigen_interop.hpp"
#include "core/common/scan_projection.hpp"
#include "core/cpu/parallel.hpp"
#include "core/cpu/pixel_lanes.hpp"
#include "core/cpu/stages.hpp"

namespace elo::cpu {

namespace {

// The driver's ring of each cloud point, when it gives them, and each ring's row.
struct RingRows {
  const uint16_t* ring_of_point;  // null: rows come from the elevation
  const int* rows;
  int count;

  int of(size_t point) const { return ring_of_point != nullptr ? ring_of_point[point] : kNoRing; }
};

}  // namespace

size_t projectCloud(const PointCloud& cloud, const SensorConfig& sensor, const SphericalProjection& projection,
                    const std::vector<int>& ring_rows, const SweepDeskew& deskew, float stamp, ClosestWins& winners,
                    std::vector<ScanPoint>& placed, ScanImage& scan) {
  const ElevationCorrection correction = ElevationCorrection::fromConfig(sensor);
  const bool use_ring = !ring_rows.empty() && cloud.ring.size() == cloud.points.size();
  const RingRows rings{use_ring ? cloud.ring.data() : nullptr, ring_rows.data(), static_cast<int>(ring_rows.size())};
  // Every placed point is kept, so that the winners need not be corrected and deskewed again.
  placed.resize(cloud.points.size());
  winners.setSingleWriter(runsAlone());
  // Each point is corrected, deskewed and timed alone; the pixels of kPixelLanes points are found at once.
  // Without a correction and a deskew a point is placed as measured, at time 0 (what scanPointVertex()
  // then gives), in a loop built without their tests.
  const auto place_points = [&](auto as_measured) {
    parallelFor((cloud.points.size() + kPixelLanes - 1) / kPixelLanes, [&](size_t group) {
      pixelsOfGroup(
          projection, group * kPixelLanes, cloud.points.size(),
          [&](size_t i, Float3& vertex) {
            const Float3 raw = toFloat3(cloud.points[i]);
            if (!isFinite(raw)) return false;
            if constexpr (decltype(as_measured)::value) {
              placed[i].measured = raw;
              placed[i].vertex = raw;
              placed[i].time = 0.0f;
            } else if (!scanPointVertex(correction, deskew, static_cast<int>(i), raw, placed[i])) {
              return false;
            }
            vertex = placed[i].vertex;
            return true;
          },
          [&](size_t i, int row, int col, float range) {
            if (!beamRow(rings.of(i), rings.rows, rings.count, projection.rows, row)) return;
            placed[i].pixel = row * projection.cols + col;
            winners.offer(placed[i].pixel, range, static_cast<uint32_t>(i));
          });
    });
  };
  if (!correction.active && deskew.timing.source == TimeSource::none && deskew.velocity.isZero()) {
    place_points(std::true_type{});
  } else {
    place_points(std::false_type{});
  }

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
