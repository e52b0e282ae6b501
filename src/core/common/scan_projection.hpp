// Sec. III-B.1: the pixel of one scan point. Both backends offer each point to its pixel, and the
// closest point wins (closest_wins_key.hpp).
#pragma once

#include "core/common/deskew.hpp"
#include "elo/sensor/projections.hpp"

namespace elo {

constexpr int kNoRing = -1;

// A cloud point as the projection places it.
struct ScanPoint {
  Float3 measured;  // after the elevation correction, in the sensor frame of its firing instant
  Float3 vertex;    // deskewed to the scan's reference instant (deskew.hpp)
  float time;       // its firing time relative to the reference instant (s)
  int pixel;
};

// The measured point, time and vertex of cloud point `index` (`raw`), as scanPointPixel() places it;
// false when it has no usable time. The CUDA projection's winners take their vertex again by this,
// without the pixel's arithmetic (the CPU projection keeps every placed point instead).
ELO_HOST_DEVICE inline bool scanPointVertex(const ElevationCorrection& correction, const SweepDeskew& deskew, int index,
                                            const Float3& raw, ScanPoint& point) {
  point.measured = correction.apply(raw);
  return deskew.apply(index, point.measured, point.time, point.vertex);
}

// The row of a point of beam `ring` into `row`: with a driver's ring (not kNoRing) the beam's row
// (`ring_rows`, `ring_count` entries), which is exact where the elevation of a noisy point is not;
// otherwise `row`, the row of its elevation, stays. False when the ring is not a known beam or its row is
// outside the `rows` of the image.
ELO_HOST_DEVICE inline bool beamRow(int ring, const int* ring_rows, int ring_count, int rows, int& row) {
  if (ring == kNoRing) return true;
  if (ring >= ring_count) return false;
  row = ring_rows[ring];
  return row >= 0 && row < rows;
}

// The pixel of cloud point `index` (`raw`), whose vertex is the point after the elevation correction and
// the deskew. `ring` (or kNoRing) is the driver's beam index: when known, the beam's row (`ring_rows`,
// `ring_count` entries) is exact where the elevation of a noisy point is not. False for a point that is
// not finite, has no usable time, is out of range or out of the image, or whose ring is not a known beam.
ELO_HOST_DEVICE inline bool scanPointPixel(const SphericalProjection& projection, const ElevationCorrection& correction,
                                           const SweepDeskew& deskew, int index, const Float3& raw, int ring,
                                           const int* ring_rows, int ring_count, ScanPoint& point) {
  if (!isFinite(raw)) return false;
  if (!scanPointVertex(correction, deskew, index, raw, point)) return false;
  int row = 0;
  int col = 0;
  if (!projection.pixelOf(point.vertex, row, col)) return false;
  if (!beamRow(ring, ring_rows, ring_count, projection.rows, row)) return false;
  point.pixel = row * projection.cols + col;
  return true;
}

}  // namespace elo
