// Sec. III-B.2 and III-C.2: projective data association of the moved scan with the model, and the
// point-to-plane sums J^T J, J^T e of each cost term. With the left update T <- exp(delta) T and
// p' = T u, the residual e = n^T (p' - v) has the Jacobian J = [n^T, (p' x n)^T] (PAPER_NOTES: the
// moved scan point, not the model vertex).
#include <cmath>

#include "core/cpu/parallel.hpp"
#include "core/cpu/stages.hpp"

namespace elo::cpu {

namespace {

struct Motion {
  Eigen::Matrix3f rotation;
  Vec3f translation;

  explicit Motion(const Eigen::Isometry3d& transform)
      : rotation(transform.linear().cast<float>()), translation(transform.translation().cast<float>()) {}
  Vec3f apply(const Vec3f& p) const { return rotation * p + translation; }
};

// Iteratively reweighted least squares with the Geman-McClure kernel; a scale of 0 weighs all equally.
double robustWeight(double residual, double scale) {
  if (scale <= 0.0) return 1.0;
  const double s2 = scale * scale;
  const double denominator = s2 + residual * residual;
  return s2 * s2 / (denominator * denominator);
}

void accumulate(const Vec3f& moved, const Vec3f& model_vertex, const Vec3f& normal, double kernel_scale,
                TermSums& sums) {
  const double residual = normal.dot(moved - model_vertex);
  const double weight = robustWeight(residual, kernel_scale);
  Vector6d J;
  J.head<3>() = normal.cast<double>();
  J.tail<3>() = moved.cross(normal).cast<double>();
  sums.JtJ.noalias() += weight * J * J.transpose();
  sums.Jte.noalias() += (weight * residual) * J;
  sums.squared_error += residual * residual;
  ++sums.inliers;
}

// Projective association (Eq. 7-8): the model pixel that `moved` projects to, when it has a normal;
// otherwise, since uneven beams leave rows empty, the model pixel with a normal nearest to `moved`
// within `radius` pixels; -1 when there is none.
int64_t nearestModelPixel(const SphericalImage& model, const Vec3f& moved, int row, int col, int radius) {
  const size_t projected = static_cast<size_t>(row) * model.cols + col;
  if (model.occupied(projected) && model.hasNormal(projected)) return static_cast<int64_t>(projected);
  int64_t best = -1;
  float best_distance = INFINITY;
  for (int r = std::max(0, row - radius); r <= std::min(model.rows - 1, row + radius); ++r) {
    for (int dc = -radius; dc <= radius; ++dc) {
      const int c = (col + dc + model.cols) % model.cols;
      const size_t pixel = static_cast<size_t>(r) * model.cols + c;
      if (!model.occupied(pixel) || !model.hasNormal(pixel)) continue;
      const float distance = (model.vertex[pixel] - moved).squaredNorm();
      if (distance < best_distance) {
        best_distance = distance;
        best = static_cast<int64_t>(pixel);
      }
    }
  }
  return best;
}

}  // namespace

std::vector<int32_t> registrationPixels(const ScanImage& scan) {
  std::vector<int32_t> pixels;
  for (size_t pixel = 0; pixel < scan.label.size(); ++pixel) {
    if (scan.label[pixel] == PixelLabel::nonground && scan.image.hasNormal(pixel)) {
      pixels.push_back(static_cast<int32_t>(pixel));
    }
  }
  return pixels;
}

TermSums nongroundSums(const ScanImage& scan, const std::vector<int32_t>& pixels, const SphericalImage& model,
                       const SphericalProjection& projection, const Eigen::Isometry3d& model_from_scan,
                       double kernel_scale, const RegistrationConfig& config) {
  const Motion motion(model_from_scan);
  const float max_distance_squared = static_cast<float>(config.max_correspondence_distance *
                                                        config.max_correspondence_distance);
  const float min_normal_cosine = static_cast<float>(std::cos(config.max_normal_angle_deg * M_PI / 180.0));
  const SphericalImage& image = scan.image;
  return deterministicSum<TermSums>(pixels.size(), [&](size_t begin, size_t end, TermSums& sums) {
    for (size_t i = begin; i < end; ++i) {
      const int32_t pixel = pixels[i];
      ++sums.candidates;
      const Vec3f moved = motion.apply(image.vertex[pixel]);
      int row = 0;
      int col = 0;
      if (!projection.pixelOf(moved, row, col)) continue;
      const int64_t match = nearestModelPixel(model, moved, row, col, config.association_radius);
      if (match < 0 || (model.vertex[match] - moved).squaredNorm() > max_distance_squared) continue;
      const Vec3f& normal = model.normal[match];
      if ((motion.rotation * image.normal[pixel]).dot(normal) < min_normal_cosine) continue;
      accumulate(moved, model.vertex[match], normal, kernel_scale, sums);
    }
  });
}

TermSums groundSums(const BevImage& scan_ground, const BevImage& model, const BevProjection& projection,
                    GroundNormalCache& normals, const Eigen::Isometry3d& model_from_scan, double kernel_scale,
                    const RegistrationConfig& registration, const BevConfig& bev) {
  const Motion motion(model_from_scan);
  const float max_distance_squared = static_cast<float>(registration.max_correspondence_distance *
                                                        registration.max_correspondence_distance);
  const int radius = bev.normal_patch_radius;
  return deterministicSum<TermSums>(scan_ground.size(), [&](size_t begin, size_t end, TermSums& sums) {
    for (size_t i = begin; i < end; ++i) {
      ++sums.candidates;
      const Vec3f moved = motion.apply(scan_ground.vertex[i]);
      int row = 0;
      int col = 0;
      if (!projection.cellOf(moved, row, col)) continue;
      // Eq. 16: the model point in the moved point's cell; where the model is sparse, the nearest around it.
      const int32_t match = nearestGroundPoint(model, projection, moved, row, col, radius);
      if (match < 0 || (model.vertex[match] - moved).squaredNorm() > max_distance_squared) continue;
      if (match < 0) continue;
      const Vec3f normal = normals.normal(model, projection, bev, match);
      if (normal.isZero()) continue;
      accumulate(moved, model.vertex[match], normal, kernel_scale, sums);
    }
  });
}

}  // namespace elo::cpu
