// The data layout every backend shares: a scan as point arrays, and images as plain row-major arrays
// (`rows x cols`, pixel index = row * cols + col). A CUDA backend mirrors these buffers one to one, so
// any stage's output can be compared element by element across backends.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "elo/device_types.hpp"  // PixelLabel

namespace elo {

using Vec3f = Eigen::Vector3f;

// One sweep of a spinning LiDAR in the sensor frame (x forward, y left, z up).
struct PointCloud {
  std::vector<Vec3f> points;
  std::vector<float> intensity;  // empty, or one per point
  std::vector<uint16_t> ring;    // empty, or the beam index of each point (0 = top beam)
  // Empty, or each point's firing time (s) relative to `stamp`: negative before it, positive after it
  // (docs/deskew.md). The odometry deskews by these with deskew.time_source `field`.
  std::vector<float> time;
  double stamp = 0.0;            // acquisition time of the sweep (s): the reference instant of `time`

  size_t size() const { return points.size(); }
};

// The ring a reader stores for a driver's ring value. A value uint16 cannot hold (negative, or past
// 65535, as a corrupt int32 field gives) would be undefined behaviour to convert; it becomes
// kUnknownRing, a beam index no sensor has, so the projection drops that point like any other ring it
// does not know.
constexpr uint16_t kUnknownRing = 0xFFFF;
inline uint16_t ringFromValue(double value) {
  return value >= 0.0 && value < kUnknownRing ? static_cast<uint16_t>(value) : kUnknownRing;
}

// A spherical range image of vertices with their normals: the scan's non-ground features and the
// non-ground model share it. A pixel is empty when its range is 0; it has no normal when its normal
// is the zero vector.
struct SphericalImage {
  int rows = 0;
  int cols = 0;
  std::vector<Vec3f> vertex;
  std::vector<Vec3f> normal;
  std::vector<float> range;
  std::vector<float> stamp;  // when the vertex was observed (s since the first scan)

  void resize(int image_rows, int image_cols);
  void clear();  // all pixels empty, size kept
  size_t pixelCount() const { return static_cast<size_t>(rows) * static_cast<size_t>(cols); }
  bool occupied(size_t pixel) const { return range[pixel] > 0.0f; }
  bool hasNormal(size_t pixel) const { return !normal[pixel].isZero(); }
  size_t countOccupied() const;
};

// The scan after projection: which cloud point each pixel holds and its label.
struct ScanImage {
  SphericalImage image;           // every projected point, deskewed; normals only on non-ground pixels
  std::vector<int32_t> point_index;  // cloud index per pixel, -1 when empty
  std::vector<PixelLabel> label;
  // Per occupied pixel of a scan with per-point times, so that the scan can be deskewed again in place:
  // its point as measured (after the elevation correction, in the sensor frame of its firing instant) and
  // its firing time relative to the scan's reference instant (s). A scan without times is not deskewed
  // again, and the CPU backend leaves these as they were.
  std::vector<Vec3f> measured;
  std::vector<float> time;

  void resize(int rows, int cols);
};

// A bird's-eye-view map of ground points (Eq. 14): cell (row, col) of a `rows x cols` grid holds at
// most one point. The grid stores only an index into compact point arrays, so a map of millions of cells
// costs 4 bytes a cell, and iterating or clearing it costs the number of points, not the grid size.
struct BevImage {
  int rows = 0;  // along y
  int cols = 0;  // along x
  std::vector<int32_t> point_of_cell;  // per cell: index of its point, -1 when empty
  // Per point, in insertion order:
  std::vector<int32_t> cell;
  std::vector<Vec3f> vertex;
  std::vector<float> range;  // distance to the sensor
  std::vector<float> stamp;  // when the point was observed (s since the first scan)

  void resize(int grid_rows, int grid_cols);
  void clear();  // no points, grid size kept
  size_t size() const { return vertex.size(); }
  size_t cellCount() const { return static_cast<size_t>(rows) * static_cast<size_t>(cols); }
  bool occupied(size_t grid_cell) const { return point_of_cell[grid_cell] >= 0; }
  // Puts the point into `grid_cell` unless the cell holds one closer to the sensor (Sec. III-D).
  void keepCloser(int32_t grid_cell, const Vec3f& point, float point_stamp);
};

// The local map, in the frame of the latest scan (Sec. III-D): the non-ground vertex and normal maps
// and the ground BEV vertex map.
struct Model {
  SphericalImage nonground;
  BevImage ground;
  bool initialized = false;
};

}  // namespace elo
