// Sec. III-D: the model update. The model lives in the frame of the latest scan: each frame, every model
// point moves into the new frame and is re-projected; where the scan also has a point the one closer to
// the sensor stays, where it has none the model's stays, and points older than tau_w go. Only three 2D
// maps are kept (vertex and normal maps of the SRI, vertex map of the BEV), so memory never grows.
#include "core/cpu/parallel.hpp"
#include "core/cpu/stages.hpp"

namespace elo::cpu {

void fuseSphericalModel(const SphericalImage& model, const ScanImage& scan, const SphericalProjection& projection,
                        const Eigen::Isometry3d& model_from_scan, float stamp, float time_window,
                        ClosestWins& winners, SphericalImage& fused) {
  const Eigen::Isometry3f scan_from_model = model_from_scan.inverse().cast<float>();
  const Eigen::Matrix3f rotation = scan_from_model.linear();
  const size_t pixels = model.pixelCount();
  const auto current = [&](size_t pixel) { return stamp - model.stamp[pixel] <= time_window; };

  // Sources 0..pixels-1 are model pixels, pixels..2*pixels-1 scan pixels; each offers itself to the
  // pixel it projects to and the closest wins.
  winners.reset();
  parallelFor(pixels, [&](size_t pixel) {
    if (!model.occupied(pixel) || !model.hasNormal(pixel) || !current(pixel)) return;
    const Vec3f moved = scan_from_model * model.vertex[pixel];
    int row = 0;
    int col = 0;
    if (!projection.pixelOf(moved, row, col)) return;
    winners.offer(static_cast<size_t>(row) * projection.cols + col, moved.norm(), static_cast<uint32_t>(pixel));
  });
  const SphericalImage& observed = scan.image;
  parallelFor(pixels, [&](size_t pixel) {
    if (scan.label[pixel] != PixelLabel::nonground || !observed.hasNormal(pixel)) return;
    winners.offer(pixel, observed.range[pixel], static_cast<uint32_t>(pixels + pixel));
  });

  parallelFor(pixels, [&](size_t pixel) {
    if (!winners.occupied(pixel)) {
      fused.range[pixel] = 0.0f;
      fused.normal[pixel].setZero();
      return;
    }
    const size_t source = winners.winner(pixel);
    if (source >= pixels) {
      const size_t from = source - pixels;
      fused.vertex[pixel] = observed.vertex[from];
      fused.normal[pixel] = observed.normal[from];
      fused.range[pixel] = observed.range[from];
      fused.stamp[pixel] = observed.stamp[from];
    } else {
      fused.vertex[pixel] = scan_from_model * model.vertex[source];
      fused.normal[pixel] = rotation * model.normal[source];
      fused.range[pixel] = fused.vertex[pixel].norm();
      fused.stamp[pixel] = model.stamp[source];
    }
  });
}

void fuseGroundModel(const BevImage& model, const BevImage& scan_ground, const BevProjection& projection,
                     const Eigen::Isometry3d& model_from_scan, float stamp, float time_window, BevImage& fused) {
  const Eigen::Isometry3f scan_from_model = model_from_scan.inverse().cast<float>();
  fused.clear();
  for (size_t point = 0; point < model.size(); ++point) {
    if (stamp - model.stamp[point] > time_window) continue;
    const Vec3f moved = scan_from_model * model.vertex[point];
    int row = 0;
    int col = 0;
    if (!projection.cellOf(moved, row, col)) continue;
    fused.keepCloser(row * projection.cols + col, moved, model.stamp[point]);
  }
  for (size_t point = 0; point < scan_ground.size(); ++point) {
    fused.keepCloser(scan_ground.cell[point], scan_ground.vertex[point], scan_ground.stamp[point]);
  }
}

void copyScanToModel(const ScanImage& scan, const BevImage& scan_ground, Model& model) {
  const SphericalImage& observed = scan.image;
  SphericalImage& target = model.nonground;
  parallelFor(observed.pixelCount(), [&](size_t pixel) {
    const bool keep = scan.label[pixel] == PixelLabel::nonground && observed.hasNormal(pixel);
    target.range[pixel] = keep ? observed.range[pixel] : 0.0f;
    target.vertex[pixel] = observed.vertex[pixel];
    target.normal[pixel] = keep ? observed.normal[pixel] : Vec3f::Zero();
    target.stamp[pixel] = observed.stamp[pixel];
  });
  model.ground.clear();
  for (size_t point = 0; point < scan_ground.size(); ++point) {
    model.ground.keepCloser(scan_ground.cell[point], scan_ground.vertex[point], scan_ground.stamp[point]);
  }
  model.initialized = true;
}

}  // namespace elo::cpu
