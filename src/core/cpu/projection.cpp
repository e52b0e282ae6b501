// Sec. III-B.1: spherical projection of the scan into an index range image, closest point per pixel, each
// point deskewed first. The per-point math is shared with the CUDA backend (scan_projection.hpp).
#include <algorithm>

#include "core/common/eigen_interop.hpp"
#include "core/common/scan_projection.hpp"
#include "core/cpu/deskew_lanes.hpp"
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

// The cloud's points as measured: without an elevation correction and a deskew, scanPointVertex() gives
// each point itself. They are read from the cloud where they are needed, not copied.
struct MeasuredPoints {
  const Vec3f* points;
  size_t count;

  template <typename Found>
  void pixelsOfGroup(const SphericalProjection& projection, size_t group, const Found& found) const {
    static_assert(sizeof(Vec3f) == 3 * sizeof(float), "a cloud's points are x, y, z after one another");
    pixelsOfPoints(projection, points->data(), group * kPixelLanes, count, found);
  }
  // Without times the scan is not deskewed again, so it keeps no measured points and times (ScanImage).
  void take(uint32_t i, Vec3f& vertex, Vec3f& /*measured*/, float& /*time*/) const { vertex = points[i]; }
};

// The cloud's points corrected, deskewed and timed (scanPointVertex()). Each one is kept as placed, so
// that the winners need not be corrected and deskewed again.
struct CorrectedPoints {
  const Vec3f* points;
  size_t count;
  ElevationCorrection correction;
  const SweepDeskew& deskew;
  ScanPoint* kept;
  bool timed;  // the points have times, so the scan keeps them and its measured points (ScanImage)

  // A whole group is placed in lanes where it can be (placeLanes()), otherwise point by point.
  template <typename Found>
  void pixelsOfGroup(const SphericalProjection& projection, size_t group, const Found& found) const {
    const size_t first = group * kPixelLanes;
#ifdef ELO_PIXEL_LANES
    PlacedLanes lanes;
    if (first + kPixelLanes <= count && placeLanes(correction, deskew, points->data(), first, kept, lanes)) {
      foundPixelsOfLanes(projection, first, lanes.usable, lanes.x, lanes.y, lanes.z, found);
      return;
    }
#endif
    cpu::pixelsOfGroup(projection, first, count, [&](size_t i, Float3& vertex) { return place(i, vertex); }, found);
  }
  void take(uint32_t i, Vec3f& vertex, Vec3f& measured, float& time) const {
    vertex = toVec3f(kept[i].vertex);
    if (!timed) return;
    measured = toVec3f(kept[i].measured);
    time = kept[i].time;
  }

 private:
  bool place(size_t i, Float3& vertex) const {
    const Float3 raw = toFloat3(points[i]);
    if (!isFinite(raw) || !scanPointVertex(correction, deskew, static_cast<int>(i), raw, kept[i])) return false;
    vertex = kept[i].vertex;
    return true;
  }
};

// Groups of points whose pixels are found before any of them is offered. Meanwhile their keys come into
// the cache: the other stages leave little of the key array there, so each offer would wait for it.
constexpr size_t kGroupsFoundAhead = 8;

// Offers every point the image accepts to its pixel, kPixelLanes points at once.
template <typename Points>
void offerPoints(const Points& points, const SphericalProjection& projection, const RingRows& rings,
                 ClosestWins& winners) {
  winners.setSingleWriter(runsAlone());
  const size_t groups = (points.count + kPixelLanes - 1) / kPixelLanes;
  parallelFor((groups + kGroupsFoundAhead - 1) / kGroupsFoundAhead, [&](size_t block) {
    size_t pixel[kGroupsFoundAhead * kPixelLanes];
    ClosestKey key[kGroupsFoundAhead * kPixelLanes];
    size_t found = 0;
    const size_t end = std::min(groups, (block + 1) * kGroupsFoundAhead);
    for (size_t group = block * kGroupsFoundAhead; group < end; ++group) {
      points.pixelsOfGroup(projection, group, [&](size_t i, int row, int col, float range) {
        if (!beamRow(rings.of(i), rings.rows, rings.count, projection.rows, row)) return;
        pixel[found] = static_cast<size_t>(row) * projection.cols + col;
        key[found] = closestWinsKey(range, static_cast<uint32_t>(i));
        winners.prefetch(pixel[found++]);
      });
    }
    for (size_t k = 0; k < found; ++k) winners.offerKey(pixel[k], key[k]);
  });
}

// Each pixel takes its winner (which empties the pixel for the next scan); returns how many have one.
// The winner's range is the one its key holds: the norm of the same vertex. The loop writes through
// plain pointers held in locals: a label is a byte, which may alias anything, so through the vectors
// every array's address would be loaded again after each label.
template <typename Points>
size_t takeWinners(const Points& points, float stamp, ClosestWins& winners, ScanImage& scan) {
  SphericalImage& image = scan.image;
  return deterministicSum<size_t>(image.pixelCount(), [&](size_t begin, size_t end, size_t& occupied) {
    const Points source = points;
    Vec3f* const vertex = image.vertex.data();
    Vec3f* const normal = image.normal.data();
    float* const range = image.range.data();
    float* const observed = image.stamp.data();
    Vec3f* const measured = scan.measured.data();
    float* const time = scan.time.data();
    int32_t* const point_index = scan.point_index.data();
    PixelLabel* const label = scan.label.data();
    size_t taken = 0;
    for (size_t pixel = begin; pixel < end; ++pixel) {
      const ClosestKey key = winners.take(pixel);
      normal[pixel].setZero();
      if (key == kNoClosestKey) {
        range[pixel] = 0.0f;
        point_index[pixel] = -1;
        label[pixel] = PixelLabel::empty;
        continue;
      }
      const uint32_t index = closestWinsSource(key);
      source.take(index, vertex[pixel], measured[pixel], time[pixel]);
      range[pixel] = closestWinsRange(key);
      observed[pixel] = stamp;
      point_index[pixel] = static_cast<int32_t>(index);
      label[pixel] = PixelLabel::nonground;
      ++taken;
    }
    occupied = taken;
  });
}

template <typename Points>
size_t projectPoints(const Points& points, const SphericalProjection& projection, const RingRows& rings, float stamp,
                     ClosestWins& winners, ScanImage& scan) {
  offerPoints(points, projection, rings, winners);
  return takeWinners(points, stamp, winners, scan);
}

}  // namespace

size_t projectCloud(const PointCloud& cloud, const SensorConfig& sensor, const SphericalProjection& projection,
                    const std::vector<int>& ring_rows, const SweepDeskew& deskew, float stamp, ClosestWins& winners,
                    std::vector<ScanPoint>& placed, ScanImage& scan) {
  const ElevationCorrection correction = ElevationCorrection::fromConfig(sensor);
  const bool use_ring = !ring_rows.empty() && cloud.ring.size() == cloud.points.size();
  const RingRows rings{use_ring ? cloud.ring.data() : nullptr, ring_rows.data(), static_cast<int>(ring_rows.size())};
  const size_t count = cloud.points.size();
  if (!correction.active && deskew.timing.source == TimeSource::none && deskew.velocity.isZero()) {
    return projectPoints(MeasuredPoints{cloud.points.data(), count}, projection, rings, stamp, winners, scan);
  }
  placed.resize(count);
  const bool timed = deskew.timing.source != TimeSource::none;
  return projectPoints(CorrectedPoints{cloud.points.data(), count, correction, deskew, placed.data(), timed},
                       projection, rings, stamp, winners, scan);
}

}  // namespace elo::cpu
