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
#include "elo/projections.hpp"

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

// Projective association (Eq. 7-8): the model pixel that `moved` projects to, when it has a normal;
// otherwise, since uneven beams leave rows empty, the model pixel with a normal nearest to `moved`
// within `radius` pixels; -1 when there is none.
template <typename SphericalModel>
ELO_HOST_DEVICE int nearestModelPixel(const SphericalModel& model, const Float3& moved, int row, int col, int radius) {
  const int projected = row * model.cols + col;
  if (model.matchable(projected)) return projected;
  int best = -1;
  float best_distance = INFINITY;
  const int first_row = row - radius < 0 ? 0 : row - radius;
  const int last_row = row + radius > model.rows - 1 ? model.rows - 1 : row + radius;
  for (int r = first_row; r <= last_row; ++r) {
    for (int dc = -radius; dc <= radius; ++dc) {
      const int pixel = r * model.cols + (col + dc + model.cols) % model.cols;
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
  match = nearestModelPixel(model, moved, row, col, gates.association_radius);
  if (match < 0 || squaredDistance(model.vertex(match), moved) > gates.max_distance_squared) return false;
  return !(dot(motion.rotate(normal), model.normal(match)) < gates.min_normal_cosine);
}

// Visits every point of `map` in the cells at Chebyshev distance `ring` from (row, col): `visit(point)`.
template <typename GroundMap, typename Visit>
ELO_HOST_DEVICE void forEachPointOnRing(const GroundMap& map, const BevProjection& projection, int row, int col,
                                        int ring, Visit& visit) {
  const int first_row = row - ring < 0 ? 0 : row - ring;
  const int last_row = row + ring > projection.rows - 1 ? projection.rows - 1 : row + ring;
  for (int r = first_row; r <= last_row; ++r) {
    const bool edge_row = r == row - ring || r == row + ring;
    const int step = edge_row || ring == 0 ? 1 : 2 * ring;  // inner rows: only the ring's two ends
    for (int c = col - ring; c <= col + ring; c += step) {
      if (c < 0 || c >= projection.cols) continue;
      const int32_t point = map.pointOfCell(r * projection.cols + c);
      if (point >= 0) visit(point);
    }
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
template <typename GroundMap>
ELO_HOST_DEVICE int32_t nearestGroundPoint(const GroundMap& map, const BevProjection& projection, const Float3& point,
                                           int row, int col, int radius) {
  for (int ring = 0; ring <= radius; ++ring) {
    detail::NearestOnRing<GroundMap> nearest{map, point};
    forEachPointOnRing(map, projection, row, col, ring, nearest);
    if (nearest.best >= 0) return nearest.best;
  }
  return -1;
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

// The normal at `centre`, a model point in cell (row, col) (Sec. III-C.2): the plane of the `wanted` model
// points nearest to it (itself included) within `patch_radius` rings of cells; zero when they give no
// plane. Rings are searched outwards; once the farthest kept point is closer than any point of the next
// ring can be (ring - 1 cells, as the centre may lie at the edge of its own cell), the rest cannot change
// the result.
template <typename GroundMap>
ELO_HOST_DEVICE Float3 groundNormalAt(const GroundMap& map, const BevProjection& projection, const Float3& centre,
                                      int row, int col, int wanted, int patch_radius) {
  detail::NearestPoints<GroundMap> nearest(map, centre, wanted);
  for (int ring = 0; ring <= patch_radius; ++ring) {
    const float ring_distance = static_cast<float>(ring - 1 > 0 ? ring - 1 : 0) * projection.cell_size;
    if (nearest.full() && nearest.farthest() <= ring_distance * ring_distance) break;
    forEachPointOnRing(map, projection, row, col, ring, nearest);
  }
  return groundPlaneNormal(nearest.points, nearest.used, centre);
}

// The normal of model point `point` of `map`: groundNormalAt() its vertex and cell.
template <typename GroundMap>
ELO_HOST_DEVICE Float3 groundNormal(const GroundMap& map, const BevProjection& projection, int32_t point, int wanted,
                                    int patch_radius) {
  const int cell = map.cell(point);
  return groundNormalAt(map, projection, map.vertex(point), cell / projection.cols, cell % projection.cols, wanted,
                        patch_radius);
}

// The cells of a ground map within `radius` of (row, col), a square of side 2 radius + 1, copied out of
// the map as a GroundMap of their own for groundNormalAt(), which reads them many times: copied first,
// the loads of a GPU thread go out all at once instead of one chain per visited cell. Slot s of the
// square (row-major) is at s * stride in each array, so that the threads of a warp can interleave their
// patches in shared memory; the points of the patch are its slots.
struct GroundPatch {
  int first_row;
  int first_col;
  int side;
  int grid_cols;
  int stride;
  uint8_t* occupied;
  float* x;
  float* y;
  float* z;

  ELO_HOST_DEVICE int slots() const { return side * side; }
  ELO_HOST_DEVICE int32_t pointOfCell(int cell) const {  // cells of the square only
    const int slot = (cell / grid_cols - first_row) * side + (cell % grid_cols - first_col);
    return occupied[slot * stride] != 0 ? slot : -1;
  }
  ELO_HOST_DEVICE Float3 vertex(int32_t slot) const { return {x[slot * stride], y[slot * stride], z[slot * stride]}; }
};

// Fills `patch` (its place and side already set) from `map`, in batches of loads that do not wait for
// one another: first the batch's cells, then their points' vertices.
template <typename GroundMap>
ELO_HOST_DEVICE void copyGroundPatch(const GroundMap& map, const BevProjection& projection, const GroundPatch& patch) {
  constexpr int kBatch = 16;
  const int slots = patch.slots();
  for (int first = 0; first < slots; first += kBatch) {
    int32_t points[kBatch];
    Float3 vertices[kBatch];
    ELO_UNROLL
    for (int i = 0; i < kBatch; ++i) {
      const int slot = first + i;
      const int row = patch.first_row + slot / patch.side;
      const int col = patch.first_col + slot % patch.side;
      const bool inside = slot < slots && row >= 0 && row < projection.rows && col >= 0 && col < projection.cols;
      points[i] = inside ? map.pointOfCell(row * projection.cols + col) : -1;
    }
    ELO_UNROLL
    for (int i = 0; i < kBatch; ++i) vertices[i] = points[i] >= 0 ? map.vertex(points[i]) : Float3{0.0f, 0.0f, 0.0f};
    ELO_UNROLL
    for (int i = 0; i < kBatch; ++i) {
      const int slot = first + i;
      if (slot >= slots) break;
      patch.occupied[slot * patch.stride] = points[i] >= 0 ? 1 : 0;
      patch.x[slot * patch.stride] = vertices[i].x;
      patch.y[slot * patch.stride] = vertices[i].y;
      patch.z[slot * patch.stride] = vertices[i].z;
    }
  }
}

}  // namespace elo
