#include "elo/types.hpp"

#include <algorithm>

#include "core/common/eigen_interop.hpp"

namespace elo {

void SphericalImage::resize(int image_rows, int image_cols) {
  rows = image_rows;
  cols = image_cols;
  const size_t pixels = pixelCount();
  vertex.assign(pixels, Vec3f::Zero());
  normal.assign(pixels, Vec3f::Zero());
  range.assign(pixels, 0.0f);
  stamp.assign(pixels, 0.0f);
}

void SphericalImage::clear() {
  std::fill(range.begin(), range.end(), 0.0f);
  std::fill(normal.begin(), normal.end(), Vec3f::Zero());
}

size_t SphericalImage::countOccupied() const {
  return static_cast<size_t>(std::count_if(range.begin(), range.end(), [](float r) { return r > 0.0f; }));
}

void ScanImage::resize(int rows, int cols) {
  image.resize(rows, cols);
  point_index.assign(image.pixelCount(), -1);
  label.assign(image.pixelCount(), PixelLabel::empty);
  measured.assign(image.pixelCount(), Vec3f::Zero());
  time.assign(image.pixelCount(), 0.0f);
}

void BevImage::resize(int grid_rows, int grid_cols) {
  rows = grid_rows;
  cols = grid_cols;
  point_of_cell.assign(cellCount(), -1);
  cell.clear();
  vertex.clear();
  range.clear();
  stamp.clear();
}

void BevImage::clear() {
  for (int32_t grid_cell : cell) point_of_cell[grid_cell] = -1;
  cell.clear();
  vertex.clear();
  range.clear();
  stamp.clear();
}

void BevImage::keepCloser(int32_t grid_cell, const Vec3f& point, float point_stamp) {
  const float point_range = norm(toFloat3(point));  // the range the CUDA backend computes
  int32_t& index = point_of_cell[grid_cell];
  if (index < 0) {
    index = static_cast<int32_t>(vertex.size());
    cell.push_back(grid_cell);
    vertex.push_back(point);
    range.push_back(point_range);
    stamp.push_back(point_stamp);
  } else if (point_range < range[index]) {
    vertex[index] = point;
    range[index] = point_range;
    stamp[index] = point_stamp;
  }
}

}  // namespace elo
