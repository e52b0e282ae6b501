// Sec. III-B.3-4: normals of the non-ground range image. The range-adaptive estimator sizes its window
// from the metric extent delta at the point's range (Eq. 12), rejects the point when most neighbours are
// far from it (sigma_r), fits a plane by eigen-decomposition, drops neighbours far from that plane
// (sigma_z) and refits; curvature then selects planar points (Eq. 11). The eigen and cross-product
// estimators are the baselines of Table III. The window size, the plane fit and the cross-product baseline
// are shared with the CUDA backend (normals.hpp), which gathers each window with a scalar loop instead.
#include <algorithm>
#include <cmath>

#include "core/common/normals.hpp"
#include "core/cpu/eigen_lanes.hpp"
#include "core/cpu/image_views.hpp"
#include "core/cpu/parallel.hpp"
#include "core/cpu/stages.hpp"

namespace elo::cpu {

namespace {

struct Window {
  int half_width;
  int half_height;
};

// Sums over the segments of a window, written as masked arithmetic over plain arrays so that the
// compiler turns each segment into a few vector instructions: a neighbour is usable (non-ground) and
// inside the window, then near (test 1) and, with kPlaneTest, on the plane (test 2). Each quantity is
// summed per lane, over the rows from the top, and the lanes are added only once, in a fixed order: a
// float sum across lanes per segment would have to be done one lane at a time (float addition is not
// associative), which cost more than the arithmetic.
template <bool kPlaneTest>
class WindowSums {
 public:
  static constexpr int kLanes = kWindowLanes;

  WindowSums(const Vec3f& centre, float distant_squared, const Vec3f& plane, float plane_distance)
      : centre_(centre),
        distant_squared_(distant_squared),
        plane_(plane),
        plane_distance_squared_(plane_distance * plane_distance) {}

  // Adds the window rows first_row to last_row around column `col`; `window` is the mask of the window's
  // half-width `half_width`. The lanes outside the window add only exact zeros (the mask zeroes them,
  // and the scratch holds no NaN), so where the window lies within the middle half of a one-block
  // segment (lanes 4 to 11) the other half is left out: the sums are the same bit for bit, at half the
  // work for the narrow windows of distant points.
  void addRows(const NormalScratch& planes, int first_row, int last_row, int col, const float* window, int half_width) {
    if (planes.span == kLanes && half_width < kLanes / 4) {
      addLanes<kLanes / 4, kLanes / 2>(planes, first_row, last_row, col, window);
    } else {
      addLanes<0, kLanes>(planes, first_row, last_row, col, window);
    }
  }

  int neighbours() const { return static_cast<int>(totals_[kNeighbours]); }
  int distant() const { return static_cast<int>(totals_[kDistant]); }

  PointMoments moments() const {
    PointMoments m;
    m.sum = {totals_[kSx], totals_[kSy], totals_[kSz]};
    m.outer = {totals_[kSxx], totals_[kSxy], totals_[kSxz], totals_[kSyy], totals_[kSyz], totals_[kSzz]};
    m.count = static_cast<int>(totals_[kCount]);
    return m;
  }

 private:
  enum Quantity { kNeighbours, kDistant, kCount, kSx, kSy, kSz, kSxx, kSxy, kSxz, kSyy, kSyz, kSzz, kQuantities };

  // Lanes kFirst to kFirst + kWidth - 1 of every segment; the others stay zero. The sums are local, so
  // the compiler knows the scratch cannot alias them and keeps them in registers across the rows.
  template <int kFirst, int kWidth>
  void addLanes(const NormalScratch& planes, int first_row, int last_row, int col, const float* __restrict window) {
    float sums[kQuantities][kWidth] = {};
    for (int r = first_row; r <= last_row; ++r) {
      // One block of lanes for the usual spans; wider ones add their blocks row by row, in order.
      for (int base = 0; base < planes.span; base += kLanes) {
        const size_t start = planes.segmentStart(r, col) + base + kFirst;
        const float* __restrict x = planes.x.data() + start;
        const float* __restrict y = planes.y.data() + start;
        const float* __restrict z = planes.z.data() + start;
        const float* __restrict usable = planes.usable.data() + start;
        const float* __restrict mask = window + base + kFirst;
        for (int i = 0; i < kWidth; ++i) {
          const float dx = x[i] - centre_.x();
          const float dy = y[i] - centre_.y();
          const float dz = z[i] - centre_.z();
          const float present = usable[i] * mask[i];
          // Selects, not branches or bool-to-float casts: both become vector blends.
          const float far = windowSquaredDistance(dx, dy, dz) > distant_squared_ ? present : 0.0f;
          float kept = present - far;  // 0 or 1: the products with it below are exact
          if constexpr (kPlaneTest) {
            const float plane_offset = windowPlaneOffset(dx, dy, dz, plane_.x(), plane_.y(), plane_.z());
            kept *= plane_offset * plane_offset > plane_distance_squared_ ? 0.0f : 1.0f;
          }
          sums[kNeighbours][i] += present;
          sums[kDistant][i] += far;
          sums[kCount][i] += kept;
          sums[kSx][i] += kept * dx;
          sums[kSy][i] += kept * dy;
          sums[kSz][i] += kept * dz;
          // The fused multiply-adds GCC would contract these into, written out, so that gatherWindow()
          // of normals.hpp (the GPU's loop) rounds the same.
          sums[kSxx][i] = fusedMultiplyAdd(kept * dx, dx, sums[kSxx][i]);
          sums[kSxy][i] = fusedMultiplyAdd(kept * dx, dy, sums[kSxy][i]);
          sums[kSxz][i] = fusedMultiplyAdd(kept * dx, dz, sums[kSxz][i]);
          sums[kSyy][i] = fusedMultiplyAdd(kept * dy, dy, sums[kSyy][i]);
          sums[kSyz][i] = fusedMultiplyAdd(kept * dy, dz, sums[kSyz][i]);
          sums[kSzz][i] = fusedMultiplyAdd(kept * dz, dz, sums[kSzz][i]);
        }
      }
    }
    // Pairwise over the lanes, always in the same order: lane i += lane i + 8, + 4, + 2, + 1.
    float lanes[kQuantities][kLanes] = {};
    for (int q = 0; q < kQuantities; ++q) {
      for (int i = 0; i < kWidth; ++i) lanes[q][kFirst + i] = sums[q][i];
    }
    static_assert(kLanes == 16, "the pairwise sum below is written out for 16 lanes");
    for (int q = 0; q < kQuantities; ++q) {
      for (int i = 0; i < 8; ++i) lanes[q][i] += lanes[q][i + 8];
      for (int i = 0; i < 4; ++i) lanes[q][i] += lanes[q][i + 4];
      for (int i = 0; i < 2; ++i) lanes[q][i] += lanes[q][i + 2];
      totals_[q] = lanes[q][0] + lanes[q][1];
    }
  }

  Vec3f centre_;
  float distant_squared_;
  Vec3f plane_;
  float plane_distance_squared_;
  float totals_[kQuantities] = {};
};

}  // namespace

void NormalScratch::fill(const ScanImage& scan, int max_window_width) {
  const int rows = scan.image.rows;
  const int cols = scan.image.cols;
  span = 16 * ((max_window_width + 15) / 16);
  stride = cols + span;
  const size_t size = static_cast<size_t>(rows) * stride;
  x.resize(size);
  y.resize(size);
  z.resize(size);
  usable.resize(size);
  const int pad = span / 2;
  parallelFor(static_cast<size_t>(rows), [&](size_t row) {
    for (int padded = 0; padded < stride; ++padded) {
      const int col = (padded - pad + cols) % cols;
      const size_t pixel = row * cols + col;
      // Other pixels keep stale vertices; zeros keep them out of the masked sums (0 * NaN would not).
      const bool is_usable = scan.label[pixel] == PixelLabel::nonground;
      const Vec3f v = is_usable ? scan.image.vertex[pixel] : Vec3f::Zero();
      const size_t at = row * stride + padded;
      x[at] = v.x();
      y[at] = v.y();
      z[at] = v.z();
      usable[at] = is_usable ? 1.0f : 0.0f;
    }
  });
  window_mask.assign(static_cast<size_t>(pad + 1) * span, 0.0f);
  for (int half = 0; half <= pad; ++half) {
    for (int lane = 0; lane < span; ++lane) {
      window_mask[static_cast<size_t>(half) * span + lane] = std::abs(lane - pad) <= half ? 1.0f : 0.0f;
    }
  }
}

WindowSize rangeAdaptiveWindow(const NormalConfig& config, const SphericalProjection& projection, float range) {
  return elo::rangeAdaptiveWindow(NormalParams::fromConfig(config, projection), range);
}

namespace {

class NormalEstimator {
 public:
  NormalEstimator(const NormalConfig& config, const SphericalProjection& projection, const NormalScratch& planes,
                  ScanImage& scan)
      : config_(config),
        params_(NormalParams::fromConfig(config, projection)),
        projection_(projection),
        planes_(planes),
        scan_(scan),
        image_(scan.image) {}

  // The normals of the pixels [begin, end). Each pixel's window is summed alone; the first plane fits of
  // kEigenLanes pixels are solved at once (eigen_lanes.hpp), giving what fitEnough() gives each.
  void estimate(size_t begin, size_t end) const {
    FirstFits pending;
    for (size_t pixel = begin; pixel < end; ++pixel) {
      if (scan_.label[pixel] != PixelLabel::nonground) continue;
      if (config_.method == NormalMethod::cross_product) {
        const int row = static_cast<int>(pixel) / projection_.cols;
        const int col = static_cast<int>(pixel) % projection_.cols;
        image_.normal[pixel] = toVec3f(crossProductNormal(ScanPixels(scan_), row, col));
        continue;
      }
      const Window window = windowOf(pixel);
      PointMoments& moments = pending.moments[pending.count];
      if (!gatherNeighbours(pixel, window, config_.method == NormalMethod::range_adaptive, nullptr, moments)) continue;
      if (moments.count < params_.min_neighbours || moments.count < 3) continue;  // fitEnough() and fitPlane() give none
      pending.pixel[pending.count] = pixel;
      pending.window[pending.count] = window;
      if (++pending.count == kEigenLanes) finish(pending);
    }
    finish(pending);
  }

 private:
  // Up to kEigenLanes pixels whose first plane fit is due.
  struct FirstFits {
    int count = 0;
    size_t pixel[kEigenLanes];
    Window window[kEigenLanes];
    PointMoments moments[kEigenLanes];
  };

  // The pending pixels' first fits, then each one's refit and curvature test as fitEnough() leaves them.
  void finish(FirstFits& pending) const {
    if (pending.count == 0) return;
    SymmetricMatrix3 covariances[kEigenLanes];
    for (int i = 0; i < pending.count; ++i) covariances[i] = pending.moments[i].covariance();
    SymmetricEigen eigens[kEigenLanes];
    symmetricEigens(covariances, pending.count, eigens);
    for (int i = 0; i < pending.count; ++i) {
      const size_t pixel = pending.pixel[i];
      PlaneFit fit = planeOf(eigens[i]);
      if (!fit.valid) continue;
      if (params_.refit) {
        PointMoments on_plane;
        gatherNeighbours(pixel, pending.window[i], true, &fit.normal, on_plane);
        if (on_plane.count != pending.moments[i].count) fit = fitEnough(on_plane, params_);
        if (!fit.valid) continue;
      }
      if (fit.curvature > config_.max_curvature) continue;
      image_.normal[pixel] = toVec3f(towardsSensor(fit.normal, toFloat3(image_.vertex[pixel])));
    }
    pending.count = 0;
  }

  Window windowOf(size_t pixel) const {
    if (config_.method == NormalMethod::eigen) {
      return {config_.max_window_width / 2, config_.max_window_height / 2};
    }
    const WindowSize size = elo::rangeAdaptiveWindow(params_, image_.range[pixel]);
    return {size.width / 2, size.height / 2};
  }

  // Accumulates the window's non-ground pixels (the centre included) as offsets from the centre. With
  // `reject_distant`, test 1 of the paper: neighbours farther than sigma_r are left out, and when they
  // are more than half of all the centre is an outlier and gets no normal (returns false). With a
  // `plane` normal, test 2: neighbours farther than sigma_z from the plane through the centre are left out.
  bool gatherNeighbours(size_t pixel, const Window& window, bool reject_distant, const Float3* plane,
                        PointMoments& moments) const {
    const Vec3f centre = image_.vertex[pixel];
    const float distant_squared =
        reject_distant ? static_cast<float>(config_.outlier_distance * config_.outlier_distance) : INFINITY;
    if (plane == nullptr) {
      WindowSums<false> sums(centre, distant_squared, Vec3f::Zero(), INFINITY);
      return sumWindow(pixel, window, sums, moments);
    }
    WindowSums<true> sums(centre, distant_squared, toVec3f(*plane), static_cast<float>(config_.plane_distance));
    return sumWindow(pixel, window, sums, moments);
  }

  template <typename Sums>
  bool sumWindow(size_t pixel, const Window& window, Sums& sums, PointMoments& moments) const {
    const int cols = projection_.cols;
    const int row = static_cast<int>(pixel) / cols;
    const int col = static_cast<int>(pixel) % cols;
    const float* mask = planes_.window_mask.data() + static_cast<size_t>(window.half_width) * planes_.span;
    sums.addRows(planes_, std::max(0, row - window.half_height), std::min(projection_.rows - 1, row + window.half_height),
                 col, mask, window.half_width);
    moments = sums.moments();
    return 2 * sums.distant() <= sums.neighbours() - 1;  // the centre is not its own neighbour
  }

  const NormalConfig& config_;
  const NormalParams params_;
  const SphericalProjection& projection_;
  const NormalScratch& planes_;
  ScanImage& scan_;
  SphericalImage& image_;
};

}  // namespace

void estimateNormals(const NormalConfig& config, const SphericalProjection& projection, NormalScratch& scratch,
                     ScanImage& scan) {
  scratch.fill(scan, config.max_window_width);
  const NormalEstimator estimator(config, projection, scratch, scan);
  parallelForBlocks(scan.image.pixelCount(), [&](size_t begin, size_t end) { estimator.estimate(begin, end); });
}

}  // namespace elo::cpu
