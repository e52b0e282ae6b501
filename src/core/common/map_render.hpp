// Localization's map rendering, per map point, as both backends draw it (cpu/map_render.cpp,
// cuda/map_render.cu): which points are ground, the disc of pixels a non-ground point covers, and the
// stand-in for an observation time that the ground map's fill ranks points by.
#pragma once

#include <cmath>

#include "elo/config.hpp"
#include "elo/device_types.hpp"
#include "elo/sensor/projections.hpp"

namespace elo {

// How a map point is drawn: the disc it covers (m), and the band of heights below the sensor where a
// point is ground (the ground segmentation's, GroundConfig) when its normal is near vertical or unknown.
struct MapRendering {
  float splat_radius;
  float ground_low;   // -sensor_height - band_below
  float ground_high;  // -sensor_height + band_above
  float same_surface_distance;

  static MapRendering fromConfig(const Config& config) {
    const GroundConfig& ground = config.ground;
    return {static_cast<float>(config.localization.splat_radius),
            static_cast<float>(-ground.sensor_height - ground.band_below),
            static_cast<float>(-ground.sensor_height + ground.band_above),
            static_cast<float>(config.model.same_surface_distance)};
  }
};

// A point in the ground band is ground unless its normal leans more than about 25 degrees.
constexpr float kMinMapGroundNormalZ = 0.9f;
// A map point's disc covers at most this many pixels either side of its own (a point closer than the
// splat radius allows would otherwise fill the image).
constexpr int kMaxSplatColumns = 4;
constexpr int kMaxSplatRows = 2;

ELO_HOST_DEVICE inline bool isMapGround(const Float3& point, const Float3& normal, const MapRendering& rendering) {
  if (!(point.z >= rendering.ground_low && point.z <= rendering.ground_high)) return false;
  return isZero(normal) || std::fabs(normal.z) >= kMinMapGroundNormalZ;
}

// A map has no observation times: the height above the band's floor stands in for the age, so that of
// the points on one surface in a cell (the ground fill's second round) the lowest, the ground rather
// than a wall's foot, wins, whatever the tie-break among equal ages would pick.
ELO_HOST_DEVICE inline float mapGroundAge(const Float3& point, const MapRendering& rendering) {
  return point.z - rendering.ground_low;
}

// The whole pixels a disc spans either side of its own, `span` pixels wide, at most `cap`. A point at the
// sensor (range 0, where sensor.min_range is 0) spans an infinite angle, or NaN without a disc: capped
// before the conversion to int, which holds neither.
ELO_HOST_DEVICE inline int splatHalfExtent(float span, int cap) {
  if (span >= static_cast<float>(cap)) return cap;
  return span > 0.0f ? static_cast<int>(span) : 0;
}

// Offers the point at (row, col), `range` away, to every pixel of the disc it spans: `offer(pixel)`.
template <typename Offer>
ELO_HOST_DEVICE void forEachSplatPixel(const SphericalProjection& projection, int row, int col, float range,
                                       float splat_radius, Offer offer) {
  const float angle = splat_radius / range;
  const float column_angle = 2.0f * static_cast<float>(M_PI) / static_cast<float>(projection.cols);
  const float row_angle = projection.fov_span / static_cast<float>(projection.rows);
  const int half_width = splatHalfExtent(angle / column_angle, kMaxSplatColumns);
  const int half_height = splatHalfExtent(angle / row_angle, kMaxSplatRows);
  const int top = row - half_height > 0 ? row - half_height : 0;
  const int bottom = row + half_height < projection.rows - 1 ? row + half_height : projection.rows - 1;
  for (int r = top; r <= bottom; ++r) {
    for (int dc = -half_width; dc <= half_width; ++dc) {
      int c = col + dc;
      if (c < 0) c += projection.cols;
      if (c >= projection.cols) c -= projection.cols;
      offer(r * projection.cols + c);
    }
  }
}

}  // namespace elo
