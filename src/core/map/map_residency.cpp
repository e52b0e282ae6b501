#include "core/map/map_residency.hpp"

#include <algorithm>

namespace elo {

namespace {

// Sorted row by row, each once.
void makeUnique(std::vector<MapTiles::Cell>& cells) {
  const auto before = [](const MapTiles::Cell& a, const MapTiles::Cell& b) {
    return a.row != b.row ? a.row < b.row : a.col < b.col;
  };
  const auto same = [](const MapTiles::Cell& a, const MapTiles::Cell& b) { return a.row == b.row && a.col == b.col; };
  std::sort(cells.begin(), cells.end(), before);
  cells.erase(std::unique(cells.begin(), cells.end(), same), cells.end());
}

}  // namespace

MapResidency::MapResidency(const MapCloud& map, double tile_size)
    : map_(map), tiles_(map, tile_size), slot_of_point_(map.size(), -1) {}

bool MapResidency::locate(const std::vector<int32_t>& points, int32_t* slots) const {
  for (size_t i = 0; i < points.size(); ++i) {
    const int32_t slot = slot_of_point_[points[i]];
    if (slot < 0) return false;
    slots[i] = slot;
  }
  return true;
}

void MapResidency::holdAround(const std::vector<int32_t>& points) {
  std::vector<MapTiles::Cell> drawn;
  for (const int32_t point : points) {
    const MapTiles::Cell cell = tiles_.cellOf(map_.points[point]);
    // A render lists its points tile by tile: one cell each, mostly.
    if (drawn.empty() || drawn.back().col != cell.col || drawn.back().row != cell.row) drawn.push_back(cell);
  }
  makeUnique(drawn);
  std::vector<MapTiles::Cell> around;
  for (const MapTiles::Cell& cell : drawn) {
    for (int64_t row = -1; row <= 1; ++row) {
      for (int64_t col = -1; col <= 1; ++col) around.push_back({cell.col + col, cell.row + row});
    }
  }
  makeUnique(around);
  release();
  for (const MapTiles::Cell& cell : around) {
    const std::vector<int32_t>* tile = tiles_.pointsIn(cell);
    if (tile == nullptr) continue;
    for (const int32_t point : *tile) {
      slot_of_point_[point] = static_cast<int32_t>(held_.size());
      held_.push_back(point);
    }
  }
}

void MapResidency::release() {
  for (const int32_t point : held_) slot_of_point_[point] = -1;
  held_.clear();
}

}  // namespace elo
