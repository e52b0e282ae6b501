// The CPU backend's ground model sorted by cell (CellOrderedGround) must find, for the registration's
// searches of association.hpp, exactly what the BEV map itself gives: the same points in the same order,
// so the same nearest point and the same ground normal bit for bit.
#include <gtest/gtest.h>

#include <cstring>
#include <random>

#include "core/common/association.hpp"
#include "core/cpu/stages.hpp"

namespace elo {
namespace {

// The BEV map as a GroundMap, one cell at a time through its grid of point indices.
struct GridGround {
  const BevImage& map;

  int32_t pointOfCell(int cell) const { return map.point_of_cell[cell]; }
  Float3 vertex(int32_t point) const { return toFloat3(map.vertex[point]); }
  int32_t cell(int32_t point) const { return map.cell[point]; }
  template <typename Visit>
  void forEachPointInCells(int first_cell, int last_cell, Visit& visit) const {
    for (int cell = first_cell; cell <= last_cell; ++cell) {
      if (map.point_of_cell[cell] >= 0) visit(map.point_of_cell[cell]);
    }
  }
};

// A 121 x 61 grid: rows are not whole 64-cell words, so row spans cross words.
BevProjection smallGrid() {
  BevConfig config;
  config.half_length = 6.05;
  config.half_width = 3.05;
  return BevProjection::fromConfig(config);
}

// A map whose points go in in random order (so the map's order is not the cells'), dense in a block
// (60 % of its cells) and sparse elsewhere, with points in the grid's edge cells. With `on_centres`,
// every point lies on its cell's centre at one height, so many candidates tie on distance.
BevImage randomMap(const BevProjection& bev, bool on_centres, std::mt19937& random) {
  BevImage map;
  map.resize(bev.rows, bev.cols);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  std::vector<int32_t> cells;
  for (int row = 0; row < bev.rows; ++row) {
    for (int col = 0; col < bev.cols; ++col) {
      const bool dense = row > 10 && row < 50 && col > 20 && col < 100;
      const bool edge = row == 0 || col == 0 || row == bev.rows - 1 || col == bev.cols - 1;
      if (unit(random) < (dense ? 0.6f : edge ? 0.3f : 0.05f)) cells.push_back(row * bev.cols + col);
    }
  }
  std::shuffle(cells.begin(), cells.end(), random);
  for (const int32_t cell : cells) {
    const float u = static_cast<float>(cell % bev.cols) + (on_centres ? 0.5f : 0.02f + 0.96f * unit(random));
    const float v = static_cast<float>(cell / bev.cols) + (on_centres ? 0.5f : 0.02f + 0.96f * unit(random));
    const Vec3f vertex(u * bev.cell_size - bev.half_length, v * bev.cell_size - bev.half_width,
                       on_centres ? -1.7f : -1.7f + 0.05f * unit(random));
    int row = 0;
    int col = 0;
    EXPECT_TRUE(bev.cellOf(vertex, row, col));
    EXPECT_EQ(row * bev.cols + col, cell);
    map.point_of_cell[cell] = static_cast<int32_t>(map.cell.size());
    map.cell.push_back(cell);
    map.vertex.push_back(vertex);
    map.range.push_back(vertex.norm());
    map.stamp.push_back(0.0f);
  }
  return map;
}

bool sameBits(const Float3& a, const Float3& b) { return std::memcmp(&a, &b, sizeof(Float3)) == 0; }

// The vertices a GroundMap visits over cells first..last of a row.
template <typename GroundMap>
std::vector<Float3> verticesInCells(const GroundMap& map, int first_cell, int last_cell) {
  std::vector<Float3> vertices;
  auto visit = [&](int32_t point) { vertices.push_back(map.vertex(point)); };
  map.forEachPointInCells(first_cell, last_cell, visit);
  return vertices;
}

TEST(CellOrderedGround, HoldsEachCellsPointAndVisitsRowSpansInCellOrder) {
  const BevProjection bev = smallGrid();
  std::mt19937 random(7);
  const BevImage map = randomMap(bev, false, random);
  const GridGround grid{map};
  cpu::CellOrderedGround sorted;
  sorted.build(map);
  ASSERT_EQ(sorted.size(), map.size());
  for (int cell = 0; cell < bev.rows * bev.cols; ++cell) {
    const int32_t point = sorted.pointOfCell(cell);
    ASSERT_EQ(point >= 0, map.occupied(cell)) << "cell " << cell;
    if (point < 0) continue;
    EXPECT_EQ(sorted.cell(point), cell);
    EXPECT_TRUE(sameBits(sorted.vertex(point), grid.vertex(map.point_of_cell[cell])));
  }
  std::uniform_int_distribution<int> any_row(0, bev.rows - 1);
  std::uniform_int_distribution<int> any_col(0, bev.cols - 1);
  for (int span = 0; span < 2000; ++span) {
    const int row_start = any_row(random) * bev.cols;
    int first = any_col(random);
    int last = any_col(random);
    if (first > last) std::swap(first, last);
    const std::vector<Float3> expected = verticesInCells(grid, row_start + first, row_start + last);
    const std::vector<Float3> found = verticesInCells(sorted, row_start + first, row_start + last);
    ASSERT_EQ(found.size(), expected.size());
    for (size_t i = 0; i < found.size(); ++i) EXPECT_TRUE(sameBits(found[i], expected[i]));
  }
}

TEST(CellOrderedGround, GivesTheMapsGroundNormalsAndNearestPointsBitForBit) {
  const BevProjection bev = smallGrid();
  std::mt19937 random(11);
  for (const bool on_centres : {false, true}) {
    const BevImage map = randomMap(bev, on_centres, random);
    const GridGround grid{map};
    cpu::CellOrderedGround sorted;
    sorted.build(map);
    for (const int radius : {1, 3, 5}) {
      for (const int neighbours : {3, 5, 8}) {
        SCOPED_TRACE("on centres " + std::to_string(on_centres) + ", radius " + std::to_string(radius) +
                     ", neighbours " + std::to_string(neighbours));
        size_t planes = 0;
        for (int32_t point = 0; point < static_cast<int32_t>(map.size()); ++point) {
          const Float3 expected = groundNormal(grid, bev, point, neighbours, radius);
          const Float3 found =
              groundNormal(sorted, bev, sorted.pointOfCell(map.cell[point]), neighbours, radius);
          ASSERT_TRUE(sameBits(found, expected)) << "point " << point;
          planes += !isZero(found);
        }
        EXPECT_GT(planes, map.size() / 2);  // the comparison covers real fits, not only empty results
      }
    }
    // Queries anywhere, in cells with and without a point, near the edges included.
    std::uniform_real_distribution<float> x(-bev.half_length, bev.half_length);
    std::uniform_real_distribution<float> y(-bev.half_width, bev.half_width);
    size_t found_by_rings = 0;
    for (int query = 0; query < 20000; ++query) {
      const Float3 p{x(random), y(random), -1.7f};
      int row = 0;
      int col = 0;
      if (!bev.cellOf(p, row, col)) continue;
      const int32_t expected = nearestGroundPoint(grid, bev, p, row, col, 3);
      const int32_t found = nearestGroundPoint(sorted, bev, p, row, col, 3);
      ASSERT_EQ(found >= 0, expected >= 0);
      if (found < 0) continue;
      EXPECT_TRUE(sameBits(sorted.vertex(found), grid.vertex(expected)));
      found_by_rings += !map.occupied(row * bev.cols + col);
    }
    EXPECT_GT(found_by_rings, 1000u);  // the ring search beyond the projected cell is covered
  }
}

TEST(CellOrderedGround, RebuildsForAChangedOrEmptiedMap) {
  const BevProjection bev = smallGrid();
  std::mt19937 random(3);
  cpu::CellOrderedGround sorted;
  sorted.build(randomMap(bev, false, random));
  const BevImage other = randomMap(bev, true, random);
  sorted.build(other);
  for (int cell = 0; cell < bev.rows * bev.cols; ++cell) ASSERT_EQ(sorted.pointOfCell(cell) >= 0, other.occupied(cell));
  BevImage empty;
  empty.resize(bev.rows, bev.cols);
  sorted.build(empty);
  EXPECT_EQ(sorted.size(), 0u);
  for (int cell = 0; cell < bev.rows * bev.cols; ++cell) ASSERT_LT(sorted.pointOfCell(cell), 0);
}

}  // namespace
}  // namespace elo
