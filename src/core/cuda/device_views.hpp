// The CUDA backend's device buffers as the kernels see them: the layout of include/elo/types.hpp (row-major
// images, BEV index grid over compact point arrays), as plain pointers, with the accessors the shared
// per-element math takes (the Image, SphericalModel and GroundMap of src/core/common). Eigen-free, so that
// nvcc and the host compiler both read it.
#pragma once

#include <cstdint>

#include "elo/device_types.hpp"

namespace elo::cuda {

// The scan after projection: every projected point, its label, and normals on non-ground pixels.
struct DeviceScan {
  int rows;
  int cols;
  Float3* vertices;
  Float3* normals;
  float* ranges;
  float* stamps;
  int32_t* point_indices;  // cloud index per pixel, -1 when empty
  PixelLabel* labels;
  Float3* measured;  // per pixel, its point as measured and its firing time (ScanImage)
  float* times;

  ELO_HOST_DEVICE int pixels() const { return rows * cols; }
  ELO_HOST_DEVICE bool occupied(int pixel) const { return ranges[pixel] > 0.0f; }
  ELO_HOST_DEVICE bool usable(int pixel) const { return labels[pixel] == PixelLabel::nonground; }
  ELO_HOST_DEVICE Float3 vertex(int pixel) const { return vertices[pixel]; }
  ELO_HOST_DEVICE float range(int pixel) const { return ranges[pixel]; }
  ELO_HOST_DEVICE void setLabel(int pixel, PixelLabel label) const { labels[pixel] = label; }
};

// The non-ground model: vertex and normal maps with observation times.
struct DeviceModelImage {
  int rows;
  int cols;
  Float3* vertices;
  Float3* normals;
  float* ranges;
  float* stamps;

  ELO_HOST_DEVICE int pixels() const { return rows * cols; }
  ELO_HOST_DEVICE bool occupied(int pixel) const { return ranges[pixel] > 0.0f; }
  ELO_HOST_DEVICE bool matchable(int pixel) const { return occupied(pixel) && !isZero(normals[pixel]); }
  ELO_HOST_DEVICE Float3 vertex(int pixel) const { return vertices[pixel]; }
  ELO_HOST_DEVICE Float3 normal(int pixel) const { return normals[pixel]; }
};

// A BEV map: per cell the index of its point (-1: empty), per point (`*count` of them) its cell, vertex,
// range and observation time.
struct DeviceBev {
  int32_t* point_of_cell;
  int32_t* cells;
  Float3* vertices;
  float* ranges;
  float* stamps;
  int* count;

  ELO_HOST_DEVICE int32_t pointOfCell(int cell) const { return point_of_cell[cell]; }
  ELO_HOST_DEVICE Float3 vertex(int32_t point) const { return vertices[point]; }
  ELO_HOST_DEVICE int32_t cell(int32_t point) const { return cells[point]; }
};

}  // namespace elo::cuda
