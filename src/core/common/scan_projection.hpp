// Sec. III-B.1: the pixel of one scan point. Both backends offer each point to its pixel, and the
// closest point wins (closest_wins_key.hpp).
#pragma once

#include "elo/projections.hpp"

namespace elo {

constexpr int kNoRing = -1;

// The pixel of raw point `raw`, and the point after the elevation correction. `ring` (or kNoRing) is the
// driver's beam index: when known, the beam's row (`ring_rows`, `ring_count` entries) is exact where the
// elevation of a noisy point is not. False for a point that is not finite, out of range or out of the
// image, or whose ring is not a known beam.
ELO_HOST_DEVICE inline bool scanPointPixel(const SphericalProjection& projection, const ElevationCorrection& correction,
                                           const Float3& raw, int ring, const int* ring_rows, int ring_count,
                                           Float3& corrected, int& pixel) {
  if (!isFinite(raw)) return false;
  corrected = correction.apply(raw);
  int row = 0;
  int col = 0;
  if (!projection.pixelOf(corrected, row, col)) return false;
  if (ring != kNoRing) {
    if (ring >= ring_count) return false;
    row = ring_rows[ring];
    if (row < 0 || row >= projection.rows) return false;
  }
  pixel = row * projection.cols + col;
  return true;
}

}  // namespace elo
