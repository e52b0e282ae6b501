// Sec. III-D: the model update. The model lives in the frame of the latest scan: each frame, every model
// point moves into the new frame and is re-projected; where the scan also has a point the one closer to
// the sensor stays, unless both lie on one surface, when the older stays; where it has none the model's
// stays, and points older than tau_w go. Only three 2D maps are kept (vertex and normal maps of the SRI,
// vertex map of the BEV), so memory never grows. The per-point rules are shared with the CUDA backend
// (model_update.hpp).
#include "core/common/eigen_interop.hpp"
#include "core/common/model_update.hpp"
#include "core/cpu/parallel.hpp"
#include "core/cpu/stages.hpp"

namespace elo::cpu {

void fuseSphericalModel(const SphericalImage& model, const ScanImage& scan, const SphericalProjection& projection,
                        const Eigen::Isometry3d& model_from_scan, const ModelFusion& fusion, ClosestWins& closest,
                        ClosestWins& winners, SphericalImage& fused) {
  const Rigid3f scan_from_model = toRigid3f(model_from_scan.inverse());
  const uint32_t pixels = static_cast<uint32_t>(model.pixelCount());
  const SphericalImage& observed = scan.image;
  // Calls offer(pixel, range, stamp, source) for every current model point, moved, and every scan point
  // that joins the model.
  const auto forEachOffer = [&](const auto& offer) {
    parallelFor(pixels, [&](size_t pixel) {
      if (!model.occupied(pixel) || !model.hasNormal(pixel)) return;
      if (!isCurrent(fusion.now, model.stamp[pixel], fusion.time_window)) return;
      const Float3 moved = scan_from_model.apply(toFloat3(model.vertex[pixel]));
      int row = 0;
      int col = 0;
      if (!projection.pixelOf(moved, row, col)) return;
      const size_t target = static_cast<size_t>(row) * projection.cols + col;
      offer(target, norm(moved), model.stamp[pixel], static_cast<uint32_t>(pixel));
    });
    parallelFor(pixels, [&](size_t pixel) {
      if (!joinsModel(scan.label[pixel], toFloat3(observed.normal[pixel]))) return;
      offer(pixel, observed.range[pixel], observed.stamp[pixel], scanSource(static_cast<uint32_t>(pixel), pixels));
    });
  };

  closest.reset();
  forEachOffer([&](size_t pixel, float range, float, uint32_t source) { closest.offer(pixel, range, source); });
  winners.reset();
  forEachOffer([&](size_t pixel, float range, float observed_at, uint32_t source) {
    if (onClosestSurface(range, closest.range(pixel), fusion.same_surface_distance)) {
      winners.offerKey(pixel, oldestWinsKey(observed_at, source));
    }
  });

  parallelFor(pixels, [&](size_t pixel) {
    if (!winners.occupied(pixel)) {
      fused.range[pixel] = 0.0f;
      fused.normal[pixel].setZero();
      return;
    }
    const uint32_t source = winners.winner(pixel);
    if (isScanSource(source, pixels)) {
      const size_t from = source - pixels;
      fused.vertex[pixel] = observed.vertex[from];
      fused.normal[pixel] = observed.normal[from];
      fused.range[pixel] = observed.range[from];
      fused.stamp[pixel] = observed.stamp[from];
    } else {
      const Float3 moved = scan_from_model.apply(toFloat3(model.vertex[source]));
      fused.vertex[pixel] = toVec3f(moved);
      fused.normal[pixel] = toVec3f(scan_from_model.rotate(toFloat3(model.normal[source])));
      fused.range[pixel] = norm(moved);
      fused.stamp[pixel] = model.stamp[source];
    }
  });
}

void fuseGroundModel(const BevImage& model, const BevImage& scan_ground, const BevProjection& projection,
                     const Eigen::Isometry3d& model_from_scan, const ModelFusion& fusion, BevImage& fused) {
  const Rigid3f scan_from_model = toRigid3f(model_from_scan.inverse());
  std::vector<GroundOffer> offers;
  offers.reserve(model.size() + scan_ground.size());
  for (size_t point = 0; point < model.size(); ++point) {
    if (!isCurrent(fusion.now, model.stamp[point], fusion.time_window)) continue;
    const Float3 moved = scan_from_model.apply(toFloat3(model.vertex[point]));
    int row = 0;
    int col = 0;
    if (!projection.cellOf(moved, row, col)) continue;
    offers.push_back({row * projection.cols + col, toVec3f(moved), model.stamp[point], static_cast<uint32_t>(point)});
  }
  const uint32_t model_points = static_cast<uint32_t>(model.size());
  for (size_t point = 0; point < scan_ground.size(); ++point) {
    offers.push_back({scan_ground.cell[point], scan_ground.vertex[point], scan_ground.stamp[point],
                      model_points + static_cast<uint32_t>(point)});
  }
  fillGroundMap(offers, fusion.same_surface_distance, fused);
}

void copyScanToModel(const ScanImage& scan, const BevImage& scan_ground, Model& model) {
  const SphericalImage& observed = scan.image;
  SphericalImage& target = model.nonground;
  parallelFor(observed.pixelCount(), [&](size_t pixel) {
    const bool keep = joinsModel(scan.label[pixel], toFloat3(observed.normal[pixel]));
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
