// Walks the cells of a uniform 2D grid over x-y that a ray crosses, in order along the ray
// (Amanatides & Woo). Both the primitive grid and the height-field ground search with it.
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>

#include "elo/sim/primitives.hpp"

namespace elo::sim {

struct GridGeometry {
  double origin_x = 0.0;  // corner of cell (0, 0)
  double origin_y = 0.0;
  double cell_size = 1.0;
  int cols = 0;  // along x
  int rows = 0;  // along y
};

// Calls visit(col, row, entry, exit) for each cell the ray crosses between the distances `begin` and
// `end` (clipped to the grid), nearest first, until visit returns false.
template <typename Visit>
void walkGrid(const GridGeometry& grid, const Ray& ray, double begin, double end, Visit&& visit) {
  constexpr double kInfinity = std::numeric_limits<double>::infinity();
  const double extent[2] = {grid.cols * grid.cell_size, grid.rows * grid.cell_size};
  const double corner[2] = {grid.origin_x, grid.origin_y};
  // Clip [begin, end] to the grid's rectangle.
  for (int axis = 0; axis < 2; ++axis) {
    const double origin = ray.origin[axis] - corner[axis];
    const double direction = ray.direction[axis];
    if (direction == 0.0) {
      if (origin < 0.0 || origin >= extent[axis]) return;
      continue;
    }
    double near = -origin / direction;
    double far = (extent[axis] - origin) / direction;
    if (near > far) std::swap(near, far);
    begin = std::max(begin, near);
    end = std::min(end, far);
  }
  if (begin > end) return;

  int cell[2];
  int step[2];
  double next_boundary[2];  // distance at which the ray leaves the current cell along each axis
  double boundary_spacing[2];
  for (int axis = 0; axis < 2; ++axis) {
    const double limit = axis == 0 ? grid.cols : grid.rows;
    const double position = (ray.origin[axis] + begin * ray.direction[axis] - corner[axis]) / grid.cell_size;
    cell[axis] = static_cast<int>(std::clamp(std::floor(position), 0.0, limit - 1.0));
    const double direction = ray.direction[axis];
    if (direction == 0.0) {
      step[axis] = 0;
      next_boundary[axis] = kInfinity;
      boundary_spacing[axis] = kInfinity;
      continue;
    }
    step[axis] = direction > 0.0 ? 1 : -1;
    const double boundary = corner[axis] + (cell[axis] + (step[axis] > 0 ? 1 : 0)) * grid.cell_size;
    next_boundary[axis] = (boundary - ray.origin[axis]) / direction;
    boundary_spacing[axis] = grid.cell_size / std::abs(direction);
  }

  double entry = begin;
  while (true) {
    const int axis = next_boundary[0] < next_boundary[1] ? 0 : 1;
    const double exit = std::min(next_boundary[axis], end);
    if (!visit(cell[0], cell[1], entry, exit)) return;
    if (exit >= end) return;
    cell[axis] += step[axis];
    if (cell[axis] < 0 || cell[axis] >= (axis == 0 ? grid.cols : grid.rows)) return;
    entry = exit;
    next_boundary[axis] += boundary_spacing[axis];
  }
}

}  // namespace elo::sim
