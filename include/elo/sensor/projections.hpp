// The projections of the paper as functions both backends call, on the host and on the GPU: the
// spherical projection Pi_S (Eq. 4), the bird's-eye-view projection Pi_G (Eq. 14) and KITTI's elevation
// correction. Eigen-free (device_types.hpp); sensor_model.hpp adds the Eigen conveniences.
#pragma once

#include <cmath>

#include "elo/device_types.hpp"

namespace elo {

struct SensorConfig;
struct BevConfig;

// atan2 with an error under 1e-5 rad (Abramowitz & Stegun 4.4.49 on the octant-reduced ratio): a pixel
// of the range image spans 3e-3 rad, and libm's atan2/asin cost more than the rest of an association.
// Both backends call this one function, so they assign points to the same pixels.
ELO_HOST_DEVICE inline float fastAtan2(float y, float x) {
  const float ax = std::fabs(x);
  const float ay = std::fabs(y);
  const float largest = ax > ay ? ax : ay;
  if (largest == 0.0f) return 0.0f;
  const float a = (ax > ay ? ay : ax) / largest;
  const float s = a * a;
  float r = a * (0.9998660f + s * (-0.3302995f + s * (0.1801410f + s * (-0.0851330f + s * 0.0208351f))));
  if (ay > ax) r = 1.57079632679f - r;
  if (x < 0.0f) r = 3.14159265359f - r;
  return y < 0.0f ? -r : r;
}

// The geometry of the spherical range image, in the form the kernels need it.
struct SphericalProjection {
  int rows = 0;
  int cols = 0;
  float fov_up = 0.0f;      // rad
  float fov_span = 0.0f;    // f_up - f_down (rad), positive
  float min_range = 0.0f;
  float max_range = 0.0f;

  static SphericalProjection fromConfig(const SensorConfig& sensor);

  // Row 0 is the top of the field of view (PAPER_NOTES: v = (f_up - phi) / (f_up - f_down) * h_S).
  ELO_HOST_DEVICE bool pixelOf(const Float3& p, int& row, int& col) const {
    const float horizontal_squared = p.x * p.x + p.y * p.y;
    const float range_squared = horizontal_squared + p.z * p.z;
    if (!(range_squared >= min_range * min_range && range_squared <= max_range * max_range)) return false;  // and NaN
    const float azimuth = fastAtan2(p.y, p.x);
    const float elevation = fastAtan2(p.z, std::sqrt(horizontal_squared));
    const float u = 0.5f * (1.0f - azimuth * static_cast<float>(M_1_PI)) * static_cast<float>(cols);
    const float v = (fov_up - elevation) / fov_span * static_cast<float>(rows);
    row = static_cast<int>(std::floor(v));
    col = static_cast<int>(std::floor(u));
    if (col >= cols) col -= cols;  // azimuth = -pi lands on the right edge: wrap
    if (col < 0) col += cols;
    return row >= 0 && row < rows;
  }
  // Host convenience for any point type with x(), y(), z() (Eigen::Vector3f).
  template <typename Point>
  bool pixelOf(const Point& p, int& row, int& col) const {
    return pixelOf(Float3{p.x(), p.y(), p.z()}, row, col);
  }

  // The row of a beam of known elevation (used with a driver's `ring` field).
  ELO_HOST_DEVICE int rowOfElevation(float elevation) const {
    return static_cast<int>(std::floor((fov_up - elevation) / fov_span * static_cast<float>(rows)));
  }
};

// The geometry of the BEV map: cell (row, col) = (floor((y + h_B) / s), floor((x + w_B) / s)).
struct BevProjection {
  int rows = 0;
  int cols = 0;
  float cell_size = 0.0f;
  float half_length = 0.0f;  // w_B, along x
  float half_width = 0.0f;   // h_B, along y

  static BevProjection fromConfig(const BevConfig& bev);

  ELO_HOST_DEVICE bool cellOf(const Float3& p, int& row, int& col) const {
    const float u = (p.x + half_length) / cell_size;
    const float v = (p.y + half_width) / cell_size;
    if (!(u >= 0.0f && v >= 0.0f)) return false;  // also rejects NaN
    col = static_cast<int>(u);
    row = static_cast<int>(v);
    return row < rows && col < cols;
  }
  // Host convenience for any point type with x(), y(), z() (Eigen::Vector3f).
  template <typename Point>
  bool cellOf(const Point& p, int& row, int& col) const {
    return cellOf(Float3{p.x(), p.y(), p.z()}, row, col);
  }
};

// Raises the elevation of a point by `angle` (rad) at constant range and azimuth: KITTI's correction.
ELO_HOST_DEVICE inline Float3 correctElevation(const Float3& p, float cos_angle, float sin_angle) {
  const float horizontal = std::sqrt(p.x * p.x + p.y * p.y);
  if (horizontal <= 0.0f) return p;
  const float new_horizontal = horizontal * cos_angle - p.z * sin_angle;
  const float scale = new_horizontal / horizontal;
  return {p.x * scale, p.y * scale, p.z * cos_angle + horizontal * sin_angle};
}

// The configured elevation correction, applied to every scan point before it is projected.
struct ElevationCorrection {
  bool active = false;
  float cos_angle = 1.0f;
  float sin_angle = 0.0f;

  static ElevationCorrection fromConfig(const SensorConfig& sensor);

  ELO_HOST_DEVICE Float3 apply(const Float3& p) const { return active ? correctElevation(p, cos_angle, sin_angle) : p; }
};

}  // namespace elo
