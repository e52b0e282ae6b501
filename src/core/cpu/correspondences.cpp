// Sec. III-B.2 and III-C.2: projective data association of the moved scan with the model, and the
// point-to-plane sums J^T J, J^T e of each cost term. The association, the gates and the term of each
// correspondence and the packed sums are shared with the CUDA backend (association.hpp,
// point_to_plane.hpp); only the order of the sums is the CPU's own (fixed blocks in double, parallel.hpp).
#include "core/common/association.hpp"
#include "core/common/point_to_plane.hpp"
#include "core/common/term_sums.hpp"
#include "core/cpu/image_views.hpp"
#include "core/cpu/packed_sums.hpp"
#include "core/cpu/parallel.hpp"
#include "core/cpu/pixel_lanes.hpp"
#include "core/cpu/stages.hpp"

namespace elo::cpu {

namespace {

// The sums of one block of correspondences, packed (point_to_plane.hpp).
struct PackedSums {
  LaneSums values;
  int candidates = 0;
  int inliers = 0;

  void add(const PointToPlane& term) {
    values.add(term);
    ++inliers;
  }
  PackedSums& operator+=(const PackedSums& other) {
    values += other.values;
    candidates += other.candidates;
    inliers += other.inliers;
    return *this;
  }
  TermSums unpacked() const {
    double packed[kTermValues];
    values.copyTo(packed);
    return unpackTermSums(packed, candidates, inliers);
  }
};

}  // namespace

std::vector<int32_t> registrationPixels(const ScanImage& scan) {
  std::vector<int32_t> pixels;
  parallelSelect(
      scan.label.size(),
      [&](size_t pixel) { return scan.label[pixel] == PixelLabel::nonground && scan.image.hasNormal(pixel); }, pixels);
  return pixels;
}

TermSums nongroundSums(const ScanImage& scan, const std::vector<int32_t>& pixels, const SphericalImage& model,
                       const SphericalProjection& projection, const Eigen::Isometry3d& model_from_scan,
                       double kernel_scale, const RegistrationConfig& config) {
  const Rigid3f motion = toRigid3f(model_from_scan);
  const CorrespondenceGates gates = CorrespondenceGates::fromConfig(config);
  const float near_range = static_cast<float>(config.near_weight_range);
  const ModelPixels model_pixels(model);
  const SphericalImage& image = scan.image;
  return deterministicSum<PackedSums>(pixels.size(), [&](size_t begin, size_t end, PackedSums& block_sums) {
    PackedSums sums;  // a local, so that the sums stay in registers over the loop
    sums.candidates = static_cast<int>(end - begin);
    // nongroundMatch() point by point, but with the pixels of 8 moved points found at once; the points
    // come to the sums in their order, as before.
    Float3 moved[kPixelLanes];
    for (size_t first = begin; first < end; first += kPixelLanes) {
      pixelsOfGroup(
          projection, first, end,
          [&](size_t i, Float3& point) {
            point = moved[i - first] = motion.apply(toFloat3(image.vertex[pixels[i]]));
            return true;
          },
          [&](size_t i, int row, int col, float) {
            const Float3& point = moved[i - first];
            int match = -1;
            if (nongroundMatchAtPixel(model_pixels, motion, point, toFloat3(image.normal[pixels[i]]), row, col, gates,
                                      match)) {
              sums.add(nongroundTerm(point, model_pixels.vertex(match), model_pixels.normal(match),
                                     image.range[pixels[i]], kernel_scale, near_range));
            }
          });
    }
    block_sums = sums;
  }).unpacked();
}

TermSums groundSums(const BevImage& scan_ground, const BevImage& model, const BevProjection& projection,
                    GroundNormalCache& normals, const Eigen::Isometry3d& model_from_scan, double kernel_scale,
                    const RegistrationConfig& registration, const BevConfig& bev) {
  const Rigid3f motion = toRigid3f(model_from_scan);
  const CorrespondenceGates gates = CorrespondenceGates::fromConfig(registration);
  const GroundPoints model_points(model);
  // Each correspondence's model normal is read (or fitted) one correspondence after its association,
  // with a prefetch in between: the cache's normals are indexed in the model's order, so most reads miss,
  // and the next association hides the wait. The sums are added in the same order as without it.
  return deterministicSum<PackedSums>(scan_ground.size(), [&](size_t begin, size_t end, PackedSums& block_sums) {
    PackedSums sums;
    Float3 pending_moved{};
    int32_t pending_match = -1;  // the previous correspondence's model point; -1: none to add
    const auto add_pending = [&] {
      const Float3 normal = toFloat3(normals.normal(model, projection, bev, pending_match));
      if (isZero(normal)) return;
      sums.add(pointToPlane(pending_moved, model_points.vertex(pending_match), normal, kernel_scale));
    };
    for (size_t i = begin; i < end; ++i) {
      ++sums.candidates;
      Float3 moved;
      int32_t match = -1;
      const bool matched = groundMatch(projection, model_points, motion, toFloat3(scan_ground.vertex[i]), gates,
                                       bev.normal_patch_radius, moved, match);
      if (!matched) continue;
      normals.prefetch(match);
      if (pending_match >= 0) add_pending();
      pending_moved = moved;
      pending_match = match;
    }
    if (pending_match >= 0) add_pending();
    block_sums = sums;
  }).unpacked();
}

}  // namespace elo::cpu
