// Sec. III-B.3-4: normals of the non-ground range image. The range-adaptive estimator sizes its window
// from the metric extent delta at the point's range (Eq. 12), rejects the point when most neighbours are
// far from it (sigma_r), fits a plane by eigen-decomposition, drops neighbours far from that plane
// (sigma_z) and refits; curvature then selects planar points (Eq. 11). The eigen and cross-product
// estimators are the baselines of Table III.
#include <algorithm>
#include <cmath>

#include "core/cpu/parallel.hpp"
#include "core/cpu/plane_fit.hpp"
#include "core/cpu/stages.hpp"

namespace elo::cpu {

namespace {

// The odd window size nearest to `pixels`, clamped: odd keeps the window centred on its pixel.
int oddWindow(double pixels, int smallest, int largest) {
  const int odd = 2 * static_cast<int>(std::floor(std::max(pixels, 0.0) / 2.0)) + 1;
  return std::clamp(odd, smallest, largest);
}

struct Window {
  int half_width;
  int half_height;
};

}  // namespace

WindowSize rangeAdaptiveWindow(const NormalConfig& config, const SphericalProjection& projection, float range) {
  const double width = config.search_size / (range * M_PI) * projection.cols;
  const double height = config.search_size / (range * projection.fov_span) * projection.rows;
  return {oddWindow(width, config.min_window_width, config.max_window_width),
          oddWindow(height, config.min_window_height, config.max_window_height)};
}

namespace {

class NormalEstimator {
 public:
  NormalEstimator(const NormalConfig& config, const SphericalProjection& projection, ScanImage& scan)
      : config_(config), projection_(projection), scan_(scan), image_(scan.image) {}

  void estimate(size_t pixel) const {
    if (scan_.label[pixel] != PixelLabel::nonground) return;
    if (config_.method == NormalMethod::cross_product) {
      image_.normal[pixel] = crossProductNormal(pixel);
      return;
    }
    const bool adaptive = config_.method == NormalMethod::range_adaptive;
    const Window window = windowOf(pixel);
    PointMoments moments;
    if (!gatherNeighbours(pixel, window, adaptive, nullptr, moments)) return;
    PlaneFit fit = fitEnough(moments);
    if (!fit.valid) return;
    // Test 2 can only drop a neighbour when sigma_z < sigma_r: |d.n| <= |d|, and test 1 already left out
    // every neighbour with |d| > sigma_r. With the paper's values (both 0.5 m) the refit is a no-op.
    if (adaptive && config_.plane_distance < config_.outlier_distance) {
      PointMoments on_plane;
      gatherNeighbours(pixel, window, true, &fit.normal, on_plane);
      if (on_plane.count != moments.count) fit = fitEnough(on_plane);
      if (!fit.valid) return;
    }
    if (fit.curvature > config_.max_curvature) return;
    image_.normal[pixel] = towardsSensor(fit.normal, image_.vertex[pixel]);
  }

 private:
  Window windowOf(size_t pixel) const {
    if (config_.method == NormalMethod::eigen) {
      return {config_.max_window_width / 2, config_.max_window_height / 2};
    }
    const WindowSize size = rangeAdaptiveWindow(config_, projection_, image_.range[pixel]);
    return {size.width / 2, size.height / 2};
  }

  bool usable(int row, int col) const {
    return row >= 0 && row < projection_.rows && scan_.label[index(row, col)] == PixelLabel::nonground;
  }
  size_t index(int row, int col) const {
    const int wrapped = (col % projection_.cols + projection_.cols) % projection_.cols;  // azimuth is circular
    return static_cast<size_t>(row) * projection_.cols + wrapped;
  }

  // Accumulates the window's non-ground pixels (the centre included) as offsets from the centre. With
  // `reject_distant`, test 1 of the paper: neighbours farther than sigma_r are left out, and when they
  // are more than half of all the centre is an outlier and gets no normal (returns false). With a
  // `plane` normal, test 2: neighbours farther than sigma_z from the plane through the centre are left out.
  bool gatherNeighbours(size_t pixel, const Window& window, bool reject_distant, const Vec3f* plane,
                        PointMoments& moments) const {
    const int cols = projection_.cols;
    const int row = static_cast<int>(pixel) / cols;
    const int col = static_cast<int>(pixel) % cols;
    const Vec3f& centre = image_.vertex[pixel];
    const float distant_squared = static_cast<float>(config_.outlier_distance * config_.outlier_distance);
    const float plane_distance = static_cast<float>(config_.plane_distance);
    int neighbours = 0;
    int distant = 0;
    for (int r = std::max(0, row - window.half_height); r <= std::min(projection_.rows - 1, row + window.half_height);
         ++r) {
      const size_t row_start = static_cast<size_t>(r) * cols;
      for (int dc = -window.half_width; dc <= window.half_width; ++dc) {
        int c = col + dc;
        c += c < 0 ? cols : (c >= cols ? -cols : 0);  // azimuth is circular
        const size_t neighbour = row_start + c;
        if (scan_.label[neighbour] != PixelLabel::nonground) continue;
        const Vec3f offset = image_.vertex[neighbour] - centre;
        ++neighbours;
        if (reject_distant && offset.squaredNorm() > distant_squared) {
          ++distant;
          continue;
        }
        if (plane && std::abs(offset.dot(*plane)) > plane_distance) continue;
        moments.add(offset);
      }
    }
    return 2 * distant <= neighbours - 1;  // the centre is not its own neighbour
  }

  PlaneFit fitEnough(const PointMoments& moments) const {
    if (moments.count < config_.min_neighbours) return {};
    return fitPlane(moments);
  }

  // The first usable pixel from (row, col) stepping by (row_step, col_step), at most two steps away.
  const Vec3f* nearestAlong(int row, int col, int row_step, int col_step) const {
    for (int step = 1; step <= 2; ++step) {
      const int r = row + step * row_step;
      const int c = col + step * col_step;
      if (usable(r, c)) return &image_.vertex[index(r, c)];
    }
    return nullptr;
  }

  Vec3f crossProductNormal(size_t pixel) const {
    const int row = static_cast<int>(pixel) / projection_.cols;
    const int col = static_cast<int>(pixel) % projection_.cols;
    const Vec3f* left = nearestAlong(row, col, 0, -1);
    const Vec3f* right = nearestAlong(row, col, 0, 1);
    const Vec3f* up = nearestAlong(row, col, -1, 0);
    const Vec3f* down = nearestAlong(row, col, 1, 0);
    if (!left || !right || !up || !down) return Vec3f::Zero();
    const Vec3f normal = (*right - *left).cross(*down - *up);
    const float length = normal.norm();
    if (!(length > 0.0f)) return Vec3f::Zero();
    return towardsSensor(normal / length, image_.vertex[pixel]);
  }

  static Vec3f towardsSensor(const Vec3f& normal, const Vec3f& point) {
    return normal.dot(point) > 0.0f ? Vec3f(-normal) : normal;
  }

  const NormalConfig& config_;
  const SphericalProjection& projection_;
  ScanImage& scan_;
  SphericalImage& image_;
};

}  // namespace

void estimateNormals(const NormalConfig& config, const SphericalProjection& projection, ScanImage& scan) {
  const NormalEstimator estimator(config, projection, scan);
  parallelFor(scan.image.pixelCount(), [&](size_t pixel) { estimator.estimate(pixel); });
}

}  // namespace elo::cpu
