// The CPU backend's images in the shapes the shared per-element math (src/core/common) takes: the
// Image, SphericalModel and GroundMap of normals.hpp, ground.hpp and association.hpp.
#pragma once

#include "core/common/eigen_interop.hpp"
#include "elo/types.hpp"

namespace elo::cpu {

// The pixels of a scan; the non-ground ones are usable for normals.
struct ScanPixels {
  explicit ScanPixels(const ScanImage& scan) : rows(scan.image.rows), cols(scan.image.cols), scan(scan) {}

  int rows;
  int cols;
  const ScanImage& scan;

  bool occupied(int pixel) const { return scan.image.occupied(pixel); }
  bool usable(int pixel) const { return scan.label[pixel] == PixelLabel::nonground; }
  Float3 vertex(int pixel) const { return toFloat3(scan.image.vertex[pixel]); }
  float range(int pixel) const { return scan.image.range[pixel]; }
};

// A scan whose pixels ground segmentation labels.
struct LabelledPixels : ScanPixels {
  explicit LabelledPixels(ScanImage& scan) : ScanPixels(scan), labels(scan.label) {}

  std::vector<PixelLabel>& labels;

  void setLabel(int pixel, PixelLabel label) const { labels[pixel] = label; }
};

// The non-ground model image, whose pixels with a normal can be matched.
struct ModelPixels {
  explicit ModelPixels(const SphericalImage& image) : rows(image.rows), cols(image.cols), image(image) {}

  int rows;
  int cols;
  const SphericalImage& image;

  bool matchable(int pixel) const { return image.occupied(pixel) && image.hasNormal(pixel); }
  Float3 vertex(int pixel) const { return toFloat3(image.vertex[pixel]); }
  Float3 normal(int pixel) const { return toFloat3(image.normal[pixel]); }
};

// The points of a BEV map.
struct GroundPoints {
  explicit GroundPoints(const BevImage& map) : map(map) {}

  const BevImage& map;

  int32_t pointOfCell(int cell) const { return map.point_of_cell[cell]; }
  Float3 vertex(int32_t point) const { return toFloat3(map.vertex[point]); }
  int32_t cell(int32_t point) const { return map.cell[point]; }
};

}  // namespace elo::cpu
