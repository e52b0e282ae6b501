// Sec. III-C.1: ground segmentation on the columns of the range image. A ground point lies in the band
// around the expected road height and rises by less than delta_theta towards the next occupied pixel
// above and below it in its column (PAPER_NOTES: the two height conditions as printed cannot both hold),
// give or take rise_tolerance: close to the sensor neighbouring rings meet the road centimetres apart,
// where delta_theta alone allows less rise than the range noise makes (docs/ground_segmentation.md).
// The CPU walks each column from top to bottom (segmentColumn()); the GPU labels each pixel on its own,
// from the column's occupancy bits (occupiedRowAbove/Below()), with the same neighbours.
//
// An Image provides `rows`, `cols`, `bool occupied(int pixel)`, `Float3 vertex(int pixel)` and
// `void setLabel(int pixel, PixelLabel label)`.
#pragma once

#include <cmath>
#include <cstdint>

#include "elo/config.hpp"
#include "elo/device_types.hpp"

namespace elo {

struct GroundBand {
  float lowest;          // -h_g - delta_h2
  float highest;         // -h_g + delta_h1
  float max_tangent;     // tan(delta_theta)
  float rise_tolerance;  // rise allowed on top of delta_theta's, m
  float min_range;       // ground.min_range, m

  static GroundBand fromConfig(const GroundConfig& config) {
    const float road = static_cast<float>(-config.sensor_height);
    return {road - static_cast<float>(config.band_below), road + static_cast<float>(config.band_above),
            static_cast<float>(std::tan(config.max_slope_deg * M_PI / 180.0)),
            static_cast<float>(config.rise_tolerance), static_cast<float>(config.min_range)};
  }
};

// Whether `point` lies nearer the sensor than `range`.
ELO_HOST_DEVICE inline bool withinRange(const Float3& point, float range) {
  return squaredNorm(point) < range * range;
}

ELO_HOST_DEVICE inline bool gentleSlope(const Float3& a, const Float3& b, const GroundBand& band) {
  const float rise = std::fabs(a.z - b.z);
  const float dx = a.x - b.x;
  const float dy = a.y - b.y;
  return rise <= band.max_tangent * std::sqrt(dx * dx + dy * dy) + band.rise_tolerance;
}

// Whether `point` is ground, given the occupied pixels above and below it in its column (null: none).
// Nearer than ground.min_range, a point in the band is ground whatever its slope, so that it enters
// neither term: not the ground map (joinsGroundMap()), and not the non-ground image as a road point that
// failed the slope test.
ELO_HOST_DEVICE inline bool isGround(const Float3& point, const Float3* above, const Float3* below,
                                     const GroundBand& band) {
  if (!(point.z > band.lowest && point.z < band.highest)) return false;
  if (withinRange(point, band.min_range)) return true;
  if (above == nullptr && below == nullptr) return false;
  if (above != nullptr && !gentleSlope(point, *above, band)) return false;
  return below == nullptr || gentleSlope(point, *below, band);
}

// The label of an occupied pixel at `point`, given its neighbours as isGround() takes them.
ELO_HOST_DEVICE inline PixelLabel groundLabel(const Float3& point, const Float3* above, const Float3* below,
                                              const GroundBand& band) {
  return isGround(point, above, below, band) ? PixelLabel::ground : PixelLabel::nonground;
}

// Whether a ground pixel at `vertex` joins the scan's ground map, so the ground term and the ground model.
ELO_HOST_DEVICE inline bool joinsGroundMap(PixelLabel label, const Float3& vertex, const GroundBand& band) {
  return label == PixelLabel::ground && !withinRange(vertex, band.min_range);
}

// Labels every occupied pixel of column `col` ground or non-ground.
template <typename Image>
ELO_HOST_DEVICE void segmentColumn(const Image& image, int col, const GroundBand& band) {
  int previous = -1;  // pixel of the occupied row above the current one
  int current = -1;
  Float3 previous_vertex{0.0f, 0.0f, 0.0f};
  Float3 current_vertex{0.0f, 0.0f, 0.0f};
  for (int row = 0; row < image.rows; ++row) {
    const int pixel = row * image.cols + col;
    if (!image.occupied(pixel)) continue;
    const Float3 vertex = image.vertex(pixel);
    if (current >= 0) {
      image.setLabel(current, groundLabel(current_vertex, previous >= 0 ? &previous_vertex : nullptr, &vertex, band));
    }
    previous = current;
    previous_vertex = current_vertex;
    current = pixel;
    current_vertex = vertex;
  }
  if (current >= 0) {
    image.setLabel(current, groundLabel(current_vertex, previous >= 0 ? &previous_vertex : nullptr, nullptr, band));
  }
}

// A column's occupancy as bits: row r is bit r % 32 of word r / 32, the words `stride` apart (the GPU
// interleaves the columns of a block). A pixel finds its neighbours of segmentColumn() from these bits in
// a few steps, without walking the column.
struct ColumnBits {
  const uint32_t* words;
  int stride;
  int count;  // (rows + 31) / 32; the bits of rows past the last are clear

  ELO_HOST_DEVICE uint32_t word(int w) const { return words[w * stride]; }
  ELO_HOST_DEVICE bool occupied(int row) const { return (word(row / 32) >> (row % 32)) & 1u; }
};

// The index of the highest and of the lowest set bit of non-zero `bits`.
ELO_HOST_DEVICE inline int highestBit(uint32_t bits) {
#ifdef __CUDA_ARCH__
  return 31 - __clz(bits);
#else
  return 31 - __builtin_clz(bits);
#endif
}
ELO_HOST_DEVICE inline int lowestBit(uint32_t bits) {
#ifdef __CUDA_ARCH__
  return __ffs(bits) - 1;
#else
  return __builtin_ctz(bits);
#endif
}

// The nearest occupied row above `row` in the column (-1: none): segmentColumn()'s `previous`.
ELO_HOST_DEVICE inline int occupiedRowAbove(const ColumnBits& column, int row) {
  int w = row / 32;
  uint32_t bits = column.word(w) & ((1u << (row % 32)) - 1u);
  while (bits == 0u && w > 0) bits = column.word(--w);
  return bits == 0u ? -1 : 32 * w + highestBit(bits);
}

// The nearest occupied row below `row` in the column (-1: none): the pixel segmentColumn() labels
// `row` at.
ELO_HOST_DEVICE inline int occupiedRowBelow(const ColumnBits& column, int row) {
  int w = row / 32;
  const int bit = row % 32;
  uint32_t bits = bit == 31 ? 0u : column.word(w) & (~0u << (bit + 1));
  while (bits == 0u && w + 1 < column.count) bits = column.word(++w);
  return bits == 0u ? -1 : 32 * w + lowestBit(bits);
}

// The label segmentColumn() gives the occupied pixel at (row, col), from the column's bits alone.
template <typename Image>
ELO_HOST_DEVICE PixelLabel pixelGroundLabel(const Image& image, const ColumnBits& column, int row, int col,
                                            const GroundBand& band) {
  const int above = occupiedRowAbove(column, row);
  const int below = occupiedRowBelow(column, row);
  const Float3 above_vertex = above >= 0 ? image.vertex(above * image.cols + col) : Float3{0.0f, 0.0f, 0.0f};
  const Float3 below_vertex = below >= 0 ? image.vertex(below * image.cols + col) : Float3{0.0f, 0.0f, 0.0f};
  return groundLabel(image.vertex(row * image.cols + col), above >= 0 ? &above_vertex : nullptr,
                     below >= 0 ? &below_vertex : nullptr, band);
}

}  // namespace elo
