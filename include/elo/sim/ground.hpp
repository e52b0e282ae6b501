// The ground: a surface z = h(x, y) that rays can hit. Worlds use a HeightField sampled from their
// analytic terrain (slopes, hills, road crown, kerbs, ditches); analytic test scenes use FlatGround.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <functional>
#include <optional>
#include <vector>

#include "elo/sim/grid_walk.hpp"
#include "elo/sim/primitives.hpp"

namespace elo::sim {

class GroundSurface {
 public:
  virtual ~GroundSurface() = default;
  virtual double height(double x, double y) const = 0;
  virtual Eigen::Vector3d normal(double x, double y) const = 0;  // unit, pointing up
  // Distance along the ray to where it first goes below the surface, within [min_distance, max_distance].
  virtual std::optional<double> intersect(const Ray& ray, double min_distance, double max_distance) const = 0;
};

// The horizontal plane z = height, intersected in closed form.
class FlatGround : public GroundSurface {
 public:
  explicit FlatGround(double height) : height_(height) {}
  double height(double, double) const override { return height_; }
  Eigen::Vector3d normal(double, double) const override { return Eigen::Vector3d::UnitZ(); }
  std::optional<double> intersect(const Ray& ray, double min_distance, double max_distance) const override;

 private:
  double height_;
};

// A surface sampled on a regular raster and interpolated bilinearly between samples. A ray finds it
// by marching: tiles and blocks whose highest sample lies below the ray are skipped whole, the rest is
// stepped one raster cell at a time until the ray is below the surface, and the crossing is then
// refined inside that step by bracketed root finding (Illinois), which is exact on planes.
class HeightField : public GroundSurface {
 public:
  using HeightFunction = std::function<double(double x, double y)>;

  // Samples `surface` (called from several threads) every `resolution` metres over the tiles within
  // `reach` of any anchor. A ray that leaves those tiles finds no ground there; height() answers
  // from `surface` itself outside them.
  HeightField(HeightFunction surface, const std::vector<Eigen::Vector2d>& anchors, double reach,
              double resolution = 0.2);

  double height(double x, double y) const override;
  Eigen::Vector3d normal(double x, double y) const override;
  std::optional<double> intersect(const Ray& ray, double min_distance, double max_distance) const override;

  double resolution() const { return resolution_; }
  size_t tileCount() const { return tiles_.size(); }

 private:
  static constexpr int kTileCells = 64;   // cells along a tile's side
  static constexpr int kBlockCells = 8;   // cells along a block's side
  static constexpr int kBlocksPerSide = kTileCells / kBlockCells;
  static constexpr int kTileSamples = kTileCells + 1;  // a tile stores its shared border, so that
                                                       // every cell interpolates within one tile

  struct Tile {
    std::vector<float> samples;  // kTileSamples^2, row-major, row = y
    std::vector<float> block_max;  // kBlocksPerSide^2: the highest sample of each block
    float max = 0.0f;
  };

  // The cell of a raster point and the offset inside it, or null when no tile covers the point.
  struct CellLookup {
    const float* corner = nullptr;  // sample (cell_x, cell_y) in its tile; +1 is x+1, +kTileSamples is y+1
    double fraction_x = 0.0;
    double fraction_y = 0.0;
  };
  CellLookup lookup(double x, double y) const;
  const Tile* tileAt(int col, int row) const;
  void selectTiles(const std::vector<Eigen::Vector2d>& anchors, double reach);
  void sampleTile(Tile& tile, int col, int row) const;
  double heightAbove(const Ray& ray, double distance) const;  // ray z minus the surface under it
  std::optional<double> march(const Ray& ray, double begin, double end) const;
  double refine(const Ray& ray, double above, double height_above, double below, double height_below) const;

  HeightFunction surface_;
  double resolution_;
  GridGeometry tile_grid_;
  std::vector<int32_t> tile_index_;  // per tile-grid cell: index into tiles_, -1 where not sampled
  std::vector<Tile> tiles_;
};

}  // namespace elo::sim
