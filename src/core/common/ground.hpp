// Sec. III-C.1: ground segmentation on the columns of the range image. A ground point lies in the band
// around the expected road height and rises by less than delta_theta towards the next occupied pixel
// above and below it in its column (PAPER_NOTES: the two height conditions as printed cannot both hold),
// give or take rise_tolerance: close to the sensor neighbouring rings meet the road centimetres apart,
// where delta_theta alone allows less rise than the range noise makes (docs/ground_segmentation.md).
// One column is one task: a CPU thread or a GPU thread walks it from top to bottom.
//
// An Image provides `rows`, `cols`, `bool occupied(int pixel)`, `Float3 vertex(int pixel)` and
// `void setLabel(int pixel, PixelLabel label)`.
#pragma once

#include <cmath>

#include "elo/config.hpp"
#include "elo/device_types.hpp"

namespace elo {

struct GroundBand {
  float lowest;          // -h_g - delta_h2
  float highest;         // -h_g + delta_h1
  float max_tangent;     // tan(delta_theta)
  float rise_tolerance;  // rise allowed on top of delta_theta's, m

  static GroundBand fromConfig(const GroundConfig& config) {
    const float road = static_cast<float>(-config.sensor_height);
    return {road - static_cast<float>(config.band_below), road + static_cast<float>(config.band_above),
            static_cast<float>(std::tan(config.max_slope_deg * M_PI / 180.0)),
            static_cast<float>(config.rise_tolerance)};
  }
};

ELO_HOST_DEVICE inline bool gentleSlope(const Float3& a, const Float3& b, const GroundBand& band) {
  const float rise = std::fabs(a.z - b.z);
  const float dx = a.x - b.x;
  const float dy = a.y - b.y;
  return rise <= band.max_tangent * std::sqrt(dx * dx + dy * dy) + band.rise_tolerance;
}

// Whether `point` is ground, given the occupied pixels above and below it in its column (null: none).
ELO_HOST_DEVICE inline bool isGround(const Float3& point, const Float3* above, const Float3* below,
                                     const GroundBand& band) {
  if (!(point.z > band.lowest && point.z < band.highest) || (above == nullptr && below == nullptr)) return false;
  if (above != nullptr && !gentleSlope(point, *above, band)) return false;
  return below == nullptr || gentleSlope(point, *below, band);
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
      const bool ground = isGround(current_vertex, previous >= 0 ? &previous_vertex : nullptr, &vertex, band);
      image.setLabel(current, ground ? PixelLabel::ground : PixelLabel::nonground);
    }
    previous = current;
    previous_vertex = current_vertex;
    current = pixel;
    current_vertex = vertex;
  }
  if (current >= 0) {
    const bool ground = isGround(current_vertex, previous >= 0 ? &previous_vertex : nullptr, nullptr, band);
    image.setLabel(current, ground ? PixelLabel::ground : PixelLabel::nonground);
  }
}

}  // namespace elo
