// Sec. III-B.3-4, Eq. 10-12: the normal of one pixel of the non-ground range image, by the range-adaptive
// estimator or the Table III baselines. The CUDA backend runs pixelNormal() once per pixel, on a tile of
// the scan in shared memory (cuda/normal_tile.hpp). The CPU backend gathers the windows with vectorised
// masked sums instead (normal_estimation.cpp) and shares the rest; gatherWindow() adds in the order and
// with the roundings of those sums, so both backends get the same normals bit for bit, which a CPU test
// checks.
//
// An Image provides `rows`, `cols`, `bool usable(int pixel)` (a non-ground pixel), `Float3 vertex(int
// pixel)` and `float range(int pixel)`.
#pragma once

#include <cmath>

#include "core/common/plane_fit.hpp"
#include "elo/config.hpp"
#include "elo/sensor/projections.hpp"

namespace elo {

// The CPU backend sums a window row in vectors of this many lanes.
constexpr int kWindowLanes = 16;

struct NormalParams {
  NormalMethod method;
  int rows;
  int cols;
  float fov_span;
  double search_size;  // delta
  int min_window_width;
  int max_window_width;
  int min_window_height;
  int max_window_height;
  int window_span;                 // lanes of a window row in the CPU's sums: the widest window, rounded up to 16
  float outlier_distance_squared;  // sigma_r^2
  float plane_distance;            // sigma_z
  // Test 2 can only drop a neighbour when sigma_z < sigma_r: |d.n| <= |d|, and test 1 already left out
  // every neighbour with |d| > sigma_r. With the paper's values (both 0.5 m) the refit is a no-op.
  bool refit;
  int min_neighbours;
  double max_curvature;

  static NormalParams fromConfig(const NormalConfig& config, const SphericalProjection& projection) {
    return {config.method,
            projection.rows,
            projection.cols,
            projection.fov_span,
            config.search_size,
            config.min_window_width,
            config.max_window_width,
            config.min_window_height,
            config.max_window_height,
            kWindowLanes * ((config.max_window_width + kWindowLanes - 1) / kWindowLanes),
            static_cast<float>(config.outlier_distance * config.outlier_distance),
            static_cast<float>(config.plane_distance),
            config.method == NormalMethod::range_adaptive && config.plane_distance < config.outlier_distance,
            config.min_neighbours,
            config.max_curvature};
  }
};

struct WindowSize {
  int width;   // l_x, pixels, odd
  int height;  // l_y, pixels, odd
};

// The odd window size nearest to `pixels`, clamped: odd keeps the window centred on its pixel.
ELO_HOST_DEVICE inline int oddWindow(double pixels, int smallest, int largest) {
  const double positive = pixels < 0.0 ? 0.0 : pixels;
  const int odd = 2 * static_cast<int>(std::floor(positive / 2.0)) + 1;
  return odd < smallest ? smallest : (largest < odd ? largest : odd);
}

// The range-adaptive window of Eq. 12 for a point at `range`.
ELO_HOST_DEVICE inline WindowSize rangeAdaptiveWindow(const NormalParams& params, float range) {
  const double width = params.search_size / (range * M_PI) * params.cols;
  const double height = params.search_size / (range * params.fov_span) * params.rows;
  return {oddWindow(width, params.min_window_width, params.max_window_width),
          oddWindow(height, params.min_window_height, params.max_window_height)};
}

ELO_HOST_DEVICE inline Float3 towardsSensor(const Float3& normal, const Float3& point) {
  return dot(normal, point) > 0.0f ? -normal : normal;
}

// Azimuth is circular. A window reaches less than a turn past either end, where one addition wraps; the
// remainders (slow on a GPU) serve the rest.
ELO_HOST_DEVICE inline int wrapColumn(int col, int cols) {
  if (col >= cols) return col - cols < cols ? col - cols : col % cols;
  if (col < 0) return col >= -cols ? col + cols : (col % cols + cols) % cols;
  return col;
}

// The arithmetic of one neighbour at offset (dx, dy, dz) from the window's centre, which the CPU
// backend's vectorised lanes and gatherWindow() both call.
ELO_HOST_DEVICE inline float windowSquaredDistance(float dx, float dy, float dz) {
  return fusedMultiplyAdd(dz, dz, fusedMultiplyAdd(dy, dy, dx * dx));
}
ELO_HOST_DEVICE inline float windowPlaneOffset(float dx, float dy, float dz, float nx, float ny, float nz) {
  return fusedMultiplyAdd(dz, nz, fusedMultiplyAdd(dy, ny, dx * nx));
}

// The CPU backend adds its 16 lanes pairwise: lane i += lane i + 8, then + 4, + 2, + 1. That is a balanced
// binary tree whose leaves, left to right, are the lanes in bit-reversed order (0, 8, 4, 12, 2, 10, ...).
// Adding each lane into the tree as soon as it is summed, taking the lanes in that order, forms the same
// additions of the same operands, while holding one pending subtree per level rather than all 16 lanes:
// a GPU thread keeps them in registers instead of spilling 16 lanes of sums to local memory.
template <int kValues>
class LaneTree {
 public:
  static constexpr int kLevels = 4;
  static_assert(kWindowLanes == 1 << kLevels, "the tree has one leaf per lane");

  // The lane that is leaf `leaf` of the tree.
  ELO_HOST_DEVICE static int laneOfLeaf(int leaf) {
    return ((leaf & 1) << 3) | ((leaf & 2) << 1) | ((leaf & 4) >> 1) | ((leaf & 8) >> 3);
  }

  // Adds the sums of leaf `leaf`; leaves come in order, from 0. After the last, `values` holds the total.
  ELO_HOST_DEVICE void add(int leaf, float (&values)[kValues]) { addAtLevel<0>(leaf, values); }

 private:
  // A level per instantiation, so that every index into pending_ is a constant and the GPU keeps it in
  // registers.
  template <int kLevel>
  ELO_HOST_DEVICE void addAtLevel(int leaf, float (&values)[kValues]) {
    if (((leaf >> kLevel) & 1) == 0) {  // a left subtree: it waits for its right sibling
      for (int q = 0; q < kValues; ++q) pending_[kLevel][q] = values[q];
      return;
    }
    for (int q = 0; q < kValues; ++q) values[q] = pending_[kLevel][q] + values[q];
    if constexpr (kLevel + 1 < kLevels) addAtLevel<kLevel + 1>(leaf, values);
  }

  float pending_[kLevels][kValues] = {};  // each read follows its write; GCC cannot tell
};

// Whether lane `lane` holds any column offset of a window of half-width `half_width` (see gatherWindow()).
ELO_HOST_DEVICE inline bool laneInWindow(int lane, int half_width, const NormalParams& params) {
  for (int segment = 0; segment < params.window_span; segment += kWindowLanes) {
    const int offset = segment + lane - params.window_span / 2;
    if (offset >= -half_width && offset <= half_width) return true;
  }
  return false;
}

// Accumulates the window's non-ground pixels (the centre included) as offsets from the centre. With
// `reject_distant`, test 1 of the paper: neighbours farther than sigma_r are left out, and when they are
// more than half of all the centre is an outlier and gets no normal (returns false). With a `plane`
// normal, test 2: neighbours farther than sigma_z from the plane through the centre are left out.
//
// The sums are formed as the CPU backend forms them: lane L of a window row holds the column offsets
// L - span/2 (+ 16, + 32 ... for wider windows), each lane sums over the rows from the top, and the 16
// lanes are then added pairwise (LaneTree). Lanes outside the window add only zeros there, which change
// no sum, so they are skipped here.
template <typename Image>
ELO_HOST_DEVICE bool gatherWindow(const Image& image, int row, int col, int half_width, int half_height,
                                  bool reject_distant, const Float3* plane, const NormalParams& params,
                                  PointMoments& moments) {
  enum { kSx, kSy, kSz, kSxx, kSxy, kSxz, kSyy, kSyz, kSzz, kSums };
  const Float3 centre = image.vertex(row * image.cols + col);
  const float plane_distance_squared = params.plane_distance * params.plane_distance;
  const int first_row = row - half_height < 0 ? 0 : row - half_height;
  const int last_row = row + half_height > image.rows - 1 ? image.rows - 1 : row + half_height;
  const int pad = params.window_span / 2;
  LaneTree<kSums> lanes;
  float sums[kSums];  // the lane's sums, then the total
  int neighbours = 0;
  int distant = 0;
  int kept = 0;
  for (int leaf = 0; leaf < kWindowLanes; ++leaf) {
    const int lane = LaneTree<kSums>::laneOfLeaf(leaf);
    for (int q = 0; q < kSums; ++q) sums[q] = 0.0f;
    for (int r = first_row; r <= last_row && laneInWindow(lane, half_width, params); ++r) {
      for (int segment = 0; segment < params.window_span; segment += kWindowLanes) {
        const int offset = segment + lane - pad;
        if (offset < -half_width || offset > half_width) continue;
        const int pixel = r * image.cols + wrapColumn(col + offset, image.cols);
        if (!image.usable(pixel)) continue;
        const Float3 vertex = image.vertex(pixel);
        const float dx = vertex.x - centre.x;
        const float dy = vertex.y - centre.y;
        const float dz = vertex.z - centre.z;
        ++neighbours;
        if (reject_distant && windowSquaredDistance(dx, dy, dz) > params.outlier_distance_squared) {
          ++distant;
          continue;
        }
        if (plane != nullptr) {
          const float plane_offset = windowPlaneOffset(dx, dy, dz, plane->x, plane->y, plane->z);
          if (plane_offset * plane_offset > plane_distance_squared) continue;
        }
        ++kept;
        sums[kSx] += dx;
        sums[kSy] += dy;
        sums[kSz] += dz;
        sums[kSxx] = fusedMultiplyAdd(dx, dx, sums[kSxx]);
        sums[kSxy] = fusedMultiplyAdd(dx, dy, sums[kSxy]);
        sums[kSxz] = fusedMultiplyAdd(dx, dz, sums[kSxz]);
        sums[kSyy] = fusedMultiplyAdd(dy, dy, sums[kSyy]);
        sums[kSyz] = fusedMultiplyAdd(dy, dz, sums[kSyz]);
        sums[kSzz] = fusedMultiplyAdd(dz, dz, sums[kSzz]);
      }
    }
    lanes.add(leaf, sums);
  }
  moments.sum = {sums[kSx], sums[kSy], sums[kSz]};
  moments.outer = {sums[kSxx], sums[kSxy], sums[kSxz], sums[kSyy], sums[kSyz], sums[kSzz]};
  moments.count = kept;
  return 2 * distant <= neighbours - 1;  // the centre is not its own neighbour
}

ELO_HOST_DEVICE inline PlaneFit fitEnough(const PointMoments& moments, const NormalParams& params) {
  if (moments.count < params.min_neighbours) return {};
  return fitPlane(moments);
}

// The eigen (fixed largest window, no outlier tests) or range-adaptive normal of the pixel at (row,
// col), which must be non-ground; zero when it has none.
template <typename Image>
ELO_HOST_DEVICE Float3 windowNormal(const Image& image, int row, int col, const NormalParams& params) {
  const Float3 none{0.0f, 0.0f, 0.0f};
  const int pixel = row * image.cols + col;
  const bool adaptive = params.method == NormalMethod::range_adaptive;
  const WindowSize size = adaptive ? rangeAdaptiveWindow(params, image.range(pixel))
                                   : WindowSize{params.max_window_width, params.max_window_height};
  PointMoments moments;
  if (!gatherWindow(image, row, col, size.width / 2, size.height / 2, adaptive, nullptr, params, moments)) return none;
  PlaneFit fit = fitEnough(moments, params);
  if (!fit.valid) return none;
  if (params.refit) {
    PointMoments on_plane;
    gatherWindow(image, row, col, size.width / 2, size.height / 2, true, &fit.normal, params, on_plane);
    if (on_plane.count != moments.count) fit = fitEnough(on_plane, params);
    if (!fit.valid) return none;
  }
  if (fit.curvature > params.max_curvature) return none;
  return towardsSensor(fit.normal, image.vertex(pixel));
}

// The cross-product baseline of Table III, SuMa's: the cross product of the two point pairs from
// (row, col) to its right and lower neighbours; zero when either is missing.
template <typename Image>
ELO_HOST_DEVICE Float3 crossProductNormal(const Image& image, int row, int col) {
  const Float3 none{0.0f, 0.0f, 0.0f};
  if (row + 1 >= image.rows) return none;
  const int pixel = row * image.cols + col;
  const int right = row * image.cols + wrapColumn(col + 1, image.cols);
  const int down = pixel + image.cols;
  if (!image.usable(right) || !image.usable(down)) return none;
  const Float3 centre = image.vertex(pixel);
  const Float3 normal = cross(image.vertex(right) - centre, image.vertex(down) - centre);
  const float length = norm(normal);
  if (!(length > 0.0f)) return none;
  return towardsSensor(normal / length, centre);
}

// The normal of a non-ground pixel by the configured method.
template <typename Image>
ELO_HOST_DEVICE Float3 pixelNormal(const Image& image, int row, int col, const NormalParams& params) {
  return params.method == NormalMethod::cross_product ? crossProductNormal(image, row, col)
                                                      : windowNormal(image, row, col, params);
}

}  // namespace elo
