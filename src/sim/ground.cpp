#include "elo/sim/ground.hpp"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace elo::sim {

std::optional<double> FlatGround::intersect(const Ray& ray, double min_distance, double max_distance) const {
  if (ray.direction.z() == 0.0) return std::nullopt;
  const double distance = (height_ - ray.origin.z()) / ray.direction.z();
  if (distance < min_distance || distance > max_distance) return std::nullopt;
  return distance;
}

HeightField::HeightField(HeightFunction surface, const std::vector<Eigen::Vector2d>& anchors, double reach,
                         double resolution)
    : surface_(std::move(surface)), resolution_(resolution) {
  selectTiles(anchors, reach);
  std::vector<std::pair<int, int>> tile_cells(tiles_.size());
  for (int row = 0; row < tile_grid_.rows; ++row) {
    for (int col = 0; col < tile_grid_.cols; ++col) {
      const int32_t index = tile_index_[static_cast<size_t>(row) * tile_grid_.cols + col];
      if (index >= 0) tile_cells[index] = {col, row};
    }
  }
  tbb::parallel_for(size_t{0}, tiles_.size(), [&](size_t index) {
    sampleTile(tiles_[index], tile_cells[index].first, tile_cells[index].second);
  });
}

void HeightField::selectTiles(const std::vector<Eigen::Vector2d>& anchors, double reach) {
  if (anchors.empty()) return;
  const double tile_size = kTileCells * resolution_;
  Eigen::Vector2d low = Eigen::Vector2d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector2d high = -low;
  for (const Eigen::Vector2d& anchor : anchors) {
    low = low.cwiseMin(anchor);
    high = high.cwiseMax(anchor);
  }
  // Tile corners on multiples of the tile size, so the raster does not depend on the anchors' extent.
  tile_grid_.cell_size = tile_size;
  tile_grid_.origin_x = std::floor((low.x() - reach) / tile_size) * tile_size;
  tile_grid_.origin_y = std::floor((low.y() - reach) / tile_size) * tile_size;
  tile_grid_.cols = static_cast<int>(std::ceil((high.x() + reach - tile_grid_.origin_x) / tile_size));
  tile_grid_.rows = static_cast<int>(std::ceil((high.y() + reach - tile_grid_.origin_y) / tile_size));
  tile_index_.assign(static_cast<size_t>(tile_grid_.cols) * tile_grid_.rows, -1);

  std::vector<bool> selected(tile_index_.size(), false);
  for (const Eigen::Vector2d& anchor : anchors) {
    const int col_begin = std::max(0, static_cast<int>((anchor.x() - reach - tile_grid_.origin_x) / tile_size));
    const int col_end = std::min(tile_grid_.cols - 1, static_cast<int>((anchor.x() + reach - tile_grid_.origin_x) / tile_size));
    const int row_begin = std::max(0, static_cast<int>((anchor.y() - reach - tile_grid_.origin_y) / tile_size));
    const int row_end = std::min(tile_grid_.rows - 1, static_cast<int>((anchor.y() + reach - tile_grid_.origin_y) / tile_size));
    for (int row = row_begin; row <= row_end; ++row) {
      for (int col = col_begin; col <= col_end; ++col) {
        // Distance from the anchor to the tile's rectangle.
        const double x0 = tile_grid_.origin_x + col * tile_size;
        const double y0 = tile_grid_.origin_y + row * tile_size;
        const double dx = std::max({x0 - anchor.x(), 0.0, anchor.x() - (x0 + tile_size)});
        const double dy = std::max({y0 - anchor.y(), 0.0, anchor.y() - (y0 + tile_size)});
        if (dx * dx + dy * dy <= reach * reach) selected[static_cast<size_t>(row) * tile_grid_.cols + col] = true;
      }
    }
  }
  for (size_t cell = 0; cell < selected.size(); ++cell) {
    if (selected[cell]) {
      tile_index_[cell] = static_cast<int32_t>(tiles_.size());
      tiles_.emplace_back();
    }
  }
}

void HeightField::sampleTile(Tile& tile, int col, int row) const {
  const double x0 = tile_grid_.origin_x + col * tile_grid_.cell_size;
  const double y0 = tile_grid_.origin_y + row * tile_grid_.cell_size;
  tile.samples.resize(kTileSamples * kTileSamples);
  for (int j = 0; j < kTileSamples; ++j) {
    for (int i = 0; i < kTileSamples; ++i) {
      tile.samples[j * kTileSamples + i] = static_cast<float>(surface_(x0 + i * resolution_, y0 + j * resolution_));
    }
  }
  // A block's bilinear surface never rises above its highest sample, its border samples included.
  tile.block_max.resize(kBlocksPerSide * kBlocksPerSide);
  for (int block_row = 0; block_row < kBlocksPerSide; ++block_row) {
    for (int block_col = 0; block_col < kBlocksPerSide; ++block_col) {
      float highest = -std::numeric_limits<float>::infinity();
      for (int j = block_row * kBlockCells; j <= (block_row + 1) * kBlockCells; ++j) {
        for (int i = block_col * kBlockCells; i <= (block_col + 1) * kBlockCells; ++i) {
          highest = std::max(highest, tile.samples[j * kTileSamples + i]);
        }
      }
      tile.block_max[block_row * kBlocksPerSide + block_col] = highest;
    }
  }
  tile.max = *std::max_element(tile.block_max.begin(), tile.block_max.end());
}

const HeightField::Tile* HeightField::tileAt(int col, int row) const {
  if (col < 0 || row < 0 || col >= tile_grid_.cols || row >= tile_grid_.rows) return nullptr;
  const int32_t index = tile_index_[static_cast<size_t>(row) * tile_grid_.cols + col];
  return index < 0 ? nullptr : &tiles_[index];
}

HeightField::CellLookup HeightField::lookup(double x, double y) const {
  const double grid_x = (x - tile_grid_.origin_x) / resolution_;
  const double grid_y = (y - tile_grid_.origin_y) / resolution_;
  const double cell_x = std::floor(grid_x);
  const double cell_y = std::floor(grid_y);
  if (!(cell_x >= 0.0 && cell_y >= 0.0)) return {};  // also rejects NaN
  const auto global_x = static_cast<int64_t>(cell_x);
  const auto global_y = static_cast<int64_t>(cell_y);
  const Tile* tile = tileAt(static_cast<int>(global_x / kTileCells), static_cast<int>(global_y / kTileCells));
  if (!tile) return {};
  const int local_x = static_cast<int>(global_x % kTileCells);
  const int local_y = static_cast<int>(global_y % kTileCells);
  return {&tile->samples[local_y * kTileSamples + local_x], grid_x - cell_x, grid_y - cell_y};
}

double HeightField::height(double x, double y) const {
  const CellLookup cell = lookup(x, y);
  if (!cell.corner) return surface_(x, y);
  const double bottom = cell.corner[0] + cell.fraction_x * (cell.corner[1] - cell.corner[0]);
  const double top = cell.corner[kTileSamples] + cell.fraction_x * (cell.corner[kTileSamples + 1] - cell.corner[kTileSamples]);
  return bottom + cell.fraction_y * (top - bottom);
}

Eigen::Vector3d HeightField::normal(double x, double y) const {
  double slope_x = 0.0;
  double slope_y = 0.0;
  const CellLookup cell = lookup(x, y);
  if (cell.corner) {
    const double s00 = cell.corner[0], s10 = cell.corner[1];
    const double s01 = cell.corner[kTileSamples], s11 = cell.corner[kTileSamples + 1];
    slope_x = ((s10 - s00) * (1.0 - cell.fraction_y) + (s11 - s01) * cell.fraction_y) / resolution_;
    slope_y = ((s01 - s00) * (1.0 - cell.fraction_x) + (s11 - s10) * cell.fraction_x) / resolution_;
  } else {
    const double step = resolution_;
    slope_x = (surface_(x + step, y) - surface_(x - step, y)) / (2.0 * step);
    slope_y = (surface_(x, y + step) - surface_(x, y - step)) / (2.0 * step);
  }
  return Eigen::Vector3d(-slope_x, -slope_y, 1.0).normalized();
}

double HeightField::heightAbove(const Ray& ray, double distance) const {
  const Eigen::Vector3d point = ray.at(distance);
  return point.z() - height(point.x(), point.y());
}

std::optional<double> HeightField::intersect(const Ray& ray, double min_distance, double max_distance) const {
  // The ray's lowest point over a stretch is at one of its ends.
  const auto lowest = [&ray](double begin, double end) {
    return std::min(ray.origin.z() + begin * ray.direction.z(), ray.origin.z() + end * ray.direction.z());
  };
  std::optional<double> hit;
  walkGrid(tile_grid_, ray, min_distance, max_distance, [&](int col, int row, double tile_entry, double tile_exit) {
    const Tile* tile = tileAt(col, row);
    if (!tile || lowest(tile_entry, tile_exit) > tile->max) return true;
    const GridGeometry blocks{tile_grid_.origin_x + col * tile_grid_.cell_size,
                              tile_grid_.origin_y + row * tile_grid_.cell_size, kBlockCells * resolution_,
                              kBlocksPerSide, kBlocksPerSide};
    walkGrid(blocks, ray, tile_entry, tile_exit, [&](int block_col, int block_row, double entry, double exit) {
      if (lowest(entry, exit) > tile->block_max[block_row * kBlocksPerSide + block_col]) return true;
      hit = march(ray, entry, exit);
      return !hit;
    });
    return !hit;
  });
  return hit;
}

std::optional<double> HeightField::march(const Ray& ray, double begin, double end) const {
  // One raster cell of horizontal travel a step: a feature narrower than that can be stepped over.
  const double horizontal = ray.direction.head<2>().norm();
  const double step = resolution_ / std::max(horizontal, 0.5);
  double distance = begin;
  double above = heightAbove(ray, distance);
  if (above <= 0.0) return distance;
  while (distance < end) {
    const double next = std::min(distance + step, end);
    const double next_above = heightAbove(ray, next);
    if (next_above <= 0.0) return refine(ray, distance, above, next, next_above);
    distance = next;
    above = next_above;
  }
  return std::nullopt;
}

double HeightField::refine(const Ray& ray, double above, double height_above, double below,
                           double height_below) const {
  // Illinois: regula falsi that halves the stale end's value when one end is kept twice, so that it
  // converges like the secant method and never leaves the bracket.
  constexpr double kTolerance = 1e-9;
  int kept_side = 0;
  for (int iteration = 0; iteration < 100; ++iteration) {
    const double guess = (above * height_below - below * height_above) / (height_below - height_above);
    const double value = heightAbove(ray, guess);
    if (std::abs(value) < kTolerance || below - above < kTolerance) return guess;
    if (value > 0.0) {
      above = guess;
      height_above = value;
      if (kept_side == -1) height_below *= 0.5;
      kept_side = -1;
    } else {
      below = guess;
      height_below = value;
      if (kept_side == 1) height_above *= 0.5;
      kept_side = 1;
    }
  }
  return 0.5 * (above + below);
}

}  // namespace elo::sim
