// Sec. III-C.2: the bird's-eye-view map of ground points, and the normals of the BEV model fitted to
// the model points nearest an associated cell (groundNormal() of association.hpp, shared with the CUDA
// backend).
#include "core/common/association.hpp"
#include "core/cpu/image_views.hpp"
#include "core/cpu/stages.hpp"

namespace elo::cpu {

void buildGroundMap(const ScanImage& scan, const BevProjection& projection, BevImage& ground) {
  ground.clear();
  const SphericalImage& image = scan.image;
  for (size_t pixel = 0; pixel < image.pixelCount(); ++pixel) {
    if (scan.label[pixel] != PixelLabel::ground) continue;
    int row = 0;
    int col = 0;
    if (!projection.cellOf(image.vertex[pixel], row, col)) continue;
    ground.keepCloser(row * projection.cols + col, image.vertex[pixel], image.stamp[pixel]);
  }
}

void GroundNormalCache::reset(size_t points) {
  if (points > capacity_) {
    capacity_ = points + points / 2;
    normals_.resize(capacity_);
    states_ = std::make_unique<std::atomic<uint8_t>[]>(capacity_);
  }
  for (size_t i = 0; i < points; ++i) states_[i].store(unknown, std::memory_order_relaxed);
}

Vec3f GroundNormalCache::normal(const BevImage& model, const BevProjection& projection, const BevConfig& config,
                                int32_t point) {
  if (states_[point].load(std::memory_order_acquire) == fitted) return normals_[point];
  const Vec3f normal =
      toVec3f(groundNormal(GroundPoints(model), projection, point, config.normal_neighbours, config.normal_patch_radius));
  uint8_t expected = unknown;
  if (states_[point].compare_exchange_strong(expected, fitting, std::memory_order_acq_rel)) {
    normals_[point] = normal;
    states_[point].store(fitted, std::memory_order_release);
  }
  return normal;
}

}  // namespace elo::cpu
