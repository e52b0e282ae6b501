// Sec. III-B.2 and III-C.2: projective data association of a moved scan point with the model, and the
// ground normals of the BEV model, for both backends.
//
// A SphericalModel provides `rows`, `cols`, `bool matchable(int pixel)` (occupied, with a normal),
// `Float3 vertex(int pixel)` and `Float3 normal(int pixel)`. A GroundMap provides `int32_t
// pointOfCell(int cell)` (-1: empty), `Float3 vertex(int32_t point)` and `int32_t cell(int32_t point)`.
#pragma once

#include <cmath>
#include <cstdint>

#include "core/common/plane_fit.hpp"
#include "elo/config.hpp"
#include "elo/sensor/projections.hpp"

namespace elo {

// The gates a correspondence must pass, in the form the kernels test them.
struct CorrespondenceGates {
  float max_distance_squared;  // between the moved scan point and its model point
  float min_normal_cosine;     // between the rotated scan normal and the model normal
  int association_radius;      // pixels searched around the projection

  static CorrespondenceGates fromConfig(const RegistrationConfig& registration) {
    return {static_cast<float>(registration.max_correspondence_distance * registration.max_correspondence_distance),
            static_cast<float>(std::cos(registration.max_normal_angle_deg * M_PI / 180.0)),
            registration.association_radius};
  }
};

// Column `col` of an image `cols` wide that closes on itself in azimuth, for col in [-cols, 2 cols):
// validate() keeps the association radius within half the image's width. A compare, not an integer
// division (a modulo per searched pixel cost more than the rest of the search).
ELO_HOST_DEVICE inline int wrappedColumn(int col, int cols) {
  if (col < 0) return col + cols;
  return col >= cols ? col - cols : col;
}

namespace detail {

// The model pixel with a normal nearest to `moved` within `radius` pixels of (row, col); -1 when none.
template <typename SphericalModel>
ELO_HOST_DEVICE int nearestModelPixelAround(const SphericalModel& model, const Float3& moved, int row, int col,
                                            int radius) {
  int best = -1;
  float best_distance = INFINITY;
  const int first_row = row - radius < 0 ? 0 : row - radius;
  const int last_row = row + radius > model.rows - 1 ? model.rows - 1 : row + radius;
  for (int r = first_row; r <= last_row; ++r) {
    const int row_start = r * model.cols;
    for (int dc = -radius; dc <= radius; ++dc) {
      const int pixel = row_start + wrappedColumn(col + dc, model.cols);
      if (!model.matchable(pixel)) continue;
      const float distance = squaredDistance(model.vertex(pixel), moved);
      if (distance < best_distance) {
        best_distance = distance;
        best = pixel;
      }
    }
  }
  return best;
}

}  // namespace detail

// Projective association (Eq. 7-8): the model pixel that `moved` projects to, when it has a normal;
// otherwise, since uneven beams leave rows empty, the model pixel with a normal nearest to `moved`
// within `radius` pixels; -1 when there is none. (The search is a function of its own so that the
// common case, the projected pixel, stays inline in the caller's loop.)
template <typename SphericalModel>
ELO_HOST_DEVICE int nearestModelPixel(const SphericalModel& model, const Float3& moved, int row, int col, int radius) {
  const int projected = row * model.cols + col;
  if (model.matchable(projected)) return projected;
  return detail::nearestModelPixelAround(model, moved, row, col, radius);
}

// The model pixel of a moved scan point `moved` (normal `normal` before `motion`) that projects to
// (row, col), when the association and the gates succeed. (The projection is the caller's, so that the
// CPU can project 8 points at once.)
template <typename SphericalModel>
ELO_HOST_DEVICE bool nongroundMatchAtPixel(const SphericalModel& model, const Rigid3f& motion, const Float3& moved,
                                           const Float3& normal, int row, int col, const CorrespondenceGates& gates,
                                           int& match) {
  match = nearestModelPixel(model, moved, row, col, gates.association_radius);
  if (match < 0 || squaredDistance(model.vertex(match), moved) > gates.max_distance_squared) return false;
  return !(dot(motion.rotate(normal), model.normal(match)) < gates.min_normal_cosine);
}

// The non-ground correspondence of scan vertex `vertex` (normal `normal`) under `motion`: the moved point
// and its model pixel, when the association and the gates succeed.
template <typename SphericalModel>
ELO_HOST_DEVICE bool nongroundMatch(const SphericalProjection& projection, const SphericalModel& model,
                                    const Rigid3f& motion, const Float3& vertex, const Float3& normal,
                                    const CorrespondenceGates& gates, Float3& moved, int& match) {
  moved = motion.apply(vertex);
  int row = 0;
  int col = 0;
  if (!projection.pixelOf(moved, row, col)) return false;
  return nongroundMatchAtPixel(model, motion, moved, normal, row, col, gates, match);
}

namespace detail {

template <typename GroundMap, typename Visit>
ELO_HOST_DEVICE void visitCell(const GroundMap& map, int cell, Visit& visit) {
  const int32_t point = map.pointOfCell(cell);
  if (point >= 0) visit(point);
}

template <typename GroundMap, typename Visit>
ELO_HOST_DEVICE void visitCells(const GroundMap& map, int first_cell, int last_cell, Visit& visit) {
  for (int cell = first_cell; cell <= last_cell; ++cell) visitCell(map, cell, visit);
}

}  // namespace detail

// Visits every point of `map` in the cells at Chebyshev distance `ring` from (row, col): `visit(point)`,
// row by row and, within a row, column by column. The top row, the two ends of the rows in between and
// the bottom row are separate loops (no test of which kind each row is).
template <typename GroundMap, typename Visit>
ELO_HOST_DEVICE void forEachPointOnRing(const GroundMap& map, const BevProjection& projection, int row, int col,
                                        int ring, Visit& visit) {
  if (ring == 0) {
    detail::visitCell(map, row * projection.cols + col, visit);
    return;
  }
  const int top = row - ring;
  const int bottom = row + ring;
  const int left = col - ring;  // the ring's two columns; either may lie outside the grid
  const int right = col + ring;
  const int first_col = left < 0 ? 0 : left;
  const int last_col = right > projection.cols - 1 ? projection.cols - 1 : right;
  if (top >= 0) detail::visitCells(map, top * projection.cols + first_col, top * projection.cols + last_col, visit);
  const int first_middle = top + 1 < 0 ? 0 : top + 1;
  const int last_middle = bottom - 1 > projection.rows - 1 ? projection.rows - 1 : bottom - 1;
  const bool left_inside = left >= 0;
  const bool right_inside = right < projection.cols;
  for (int r = first_middle; r <= last_middle; ++r) {
    const int row_start = r * projection.cols;
    if (left_inside) detail::visitCell(map, row_start + left, visit);
    if (right_inside) detail::visitCell(map, row_start + right, visit);
  }
  if (bottom < projection.rows) {
    detail::visitCells(map, bottom * projection.cols + first_col, bottom * projection.cols + last_col, visit);
  }
}

namespace detail {

template <typename GroundMap>
struct NearestOnRing {
  const GroundMap& map;
  Float3 point;
  int32_t best = -1;
  float best_distance = INFINITY;

  ELO_HOST_DEVICE void operator()(int32_t candidate) {
    const float distance = squaredDistance(map.vertex(candidate), point);
    if (distance < best_distance) {
      best_distance = distance;
      best = candidate;
    }
  }
};

// The point of `map` nearest to `point` in the first ring of cells around (row, col), from ring 1 up to
// `radius`, that holds any; -1 when none does.
template <typename GroundMap>
ELO_HOST_DEVICE int32_t nearestGroundPointOnRings(const GroundMap& map, const BevProjection& projection,
                                                  const Float3& point, int row, int col, int radius) {
  for (int ring = 1; ring <= radius; ++ring) {
    NearestOnRing<GroundMap> nearest{map, point};
    forEachPointOnRing(map, projection, row, col, ring, nearest);
    if (nearest.best >= 0) return nearest.best;
  }
  return -1;
}

// Upper bound of bev.normal_neighbours (validate() enforces it), the size of the fit's fixed buffers.
constexpr int kMaxNormalNeighbours = 32;

// The `wanted` points nearest to `centre`, kept sorted by distance in fixed buffers.
template <typename GroundMap>
struct NearestPoints {
  // The buffers are filled before they are read (up to `used`): no need to clear them.
  ELO_HOST_DEVICE NearestPoints(const GroundMap& map, const Float3& centre, int wanted)
      : map(map), centre(centre), wanted(wanted < kMaxNormalNeighbours ? wanted : kMaxNormalNeighbours) {}

  const GroundMap& map;
  Float3 centre;
  int wanted;
  int used = 0;
  float distances[kMaxNormalNeighbours];
  Float3 points[kMaxNormalNeighbours];

  ELO_HOST_DEVICE bool full() const { return used == wanted; }
  ELO_HOST_DEVICE float farthest() const { return distances[used - 1]; }

  ELO_HOST_DEVICE void operator()(int32_t other) {
    const Float3 vertex = map.vertex(other);
    const float distance = squaredDistance(vertex, centre);
    if (full() && distance >= farthest()) return;
    int slot = used < wanted ? used++ : used - 1;
    for (; slot > 0 && distances[slot - 1] > distance; --slot) {
      distances[slot] = distances[slot - 1];
      points[slot] = points[slot - 1];
    }
    distances[slot] = distance;
    points[slot] = vertex;
  }
};

}  // namespace detail

// The point of `map` nearest to `point` in the cell of (row, col), or else in the first ring of cells
// around it that holds any, up to `radius` rings out; -1 when there is none.
// (The ring search is a function of its own so that the common case, a point in the cell itself, stays
// inline in the caller's loop.)
template <typename GroundMap>
ELO_HOST_DEVICE int32_t nearestGroundPoint(const GroundMap& map, const BevProjection& projection, const Float3& point,
                                           int row, int col, int radius) {
  const int32_t in_cell = map.pointOfCell(row * projection.cols + col);  // ring 0: the one point it may hold
  if (in_cell >= 0) return in_cell;
  return detail::nearestGroundPointOnRings(map, projection, point, row, col, radius);
}

// The ground correspondence of scan ground vertex `vertex` under `motion` (Eq. 16): the model point in
// the moved point's cell, or where the model is sparse the nearest around it up to `patch_radius` rings
// out, within the distance gate.
template <typename GroundMap>
ELO_HOST_DEVICE bool groundMatch(const BevProjection& projection, const GroundMap& model, const Rigid3f& motion,
                                 const Float3& vertex, const CorrespondenceGates& gates, int patch_radius,
                                 Float3& moved, int32_t& match) {
  moved = motion.apply(vertex);
  int row = 0;
  int col = 0;
  if (!projection.cellOf(moved, row, col)) return false;
  match = nearestGroundPoint(model, projection, moved, row, col, patch_radius);
  return match >= 0 && !(squaredDistance(model.vertex(match), moved) > gates.max_distance_squared);
}

// The normal of model point `point` (Sec. III-C.2): the plane of the `wanted` model points nearest to it
// (itself included) within `patch_radius` rings of cells; zero when they give no plane. Rings are
// searched outwards; once the farthest kept point is closer than any point of the next ring can be
// (ring - 1 cells, as the centre may lie at the edge of its own cell), the rest cannot change the result.
template <typename GroundMap>
ELO_HOST_DEVICE Float3 groundNormal(const GroundMap& map, const BevProjection& projection, int32_t point, int wanted,
                                    int patch_radius) {
  const Float3 centre = map.vertex(point);
  const int cell = map.cell(point);
  const int row = cell / projection.cols;
  const int col = cell % projection.cols;
  detail::NearestPoints<GroundMap> nearest(map, centre, wanted);
  for (int ring = 0; ring <= patch_radius; ++ring) {
    const float ring_distance = static_cast<float>(ring - 1 > 0 ? ring - 1 : 0) * projection.cell_size;
    if (nearest.full() && nearest.farthest() <= ring_distance * ring_distance) break;
    forEachPointOnRing(map, projection, row, col, ring, nearest);
  }
  return groundPlaneNormal(nearest.points, nearest.used, centre);
}

}  // namespace elo
