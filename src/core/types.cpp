#include "elo/types.hpp"

#include <algorithm>

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
}

void ScanImage::clear() {
  image.clear();
  std::fill(point_index.begin(), point_index.end(), -1);
  std::fill(label.begin(), label.end(), PixelLabel::empty);
}

void BevImage::resize(int image_rows, int image_cols) {
  rows = image_rows;
  cols = image_cols;
  vertex.assign(cellCount(), Vec3f::Zero());
  range.assign(cellCount(), 0.0f);
  stamp.assign(cellCount(), 0.0f);
  occupied_cells.clear();
}

void BevImage::clear() {
  for (int32_t cell : occupied_cells) range[cell] = 0.0f;
  occupied_cells.clear();
}

}  // namespace elo
