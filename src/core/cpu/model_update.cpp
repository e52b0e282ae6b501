// Sec. III-D: the model update. The model lives in the frame of the latest scan: each frame, every model
// point moves into the new frame and is re-projected; where the scan also has a point the one closer to
// the sensor stays, unless both lie on one surface, when the older stays; where it has none the model's
// stays, and points older than tau_w go. Only three 2D maps are kept (vertex and normal maps of the SRI,
// vertex map of the BEV), so memory never grows. The per-point rules are shared with the CUDA backend
// (model_update.hpp).
#include <vector>

#include "core/common/eigen_interop.hpp"
#include "core/common/model_update.hpp"
#include "core/cpu/parallel.hpp"
#include "core/cpu/stages.hpp"

namespace elo::cpu {

void SphericalFusionScratch::resize(size_t pixels) {
  closest.resize(pixels);
  oldest.resize(pixels);
  moved_pixel.resize(pixels);
  moved_range.resize(pixels);
}

namespace {

// Moves model pixel `pixel` into the scan's frame and notes where it lands: -1 when it is not offered
// (empty, no normal, expired, or out of the image).
void moveModelPoint(const SphericalImage& model, size_t pixel, const Rigid3f& scan_from_model,
                    const SphericalProjection& projection, const ModelFusion& fusion, SphericalFusionScratch& scratch) {
  scratch.moved_pixel[pixel] = -1;
  if (!model.occupied(pixel) || !model.hasNormal(pixel)) return;
  if (!isCurrent(fusion.now, model.stamp[pixel], fusion.time_window)) return;
  const Float3 moved = scan_from_model.apply(toFloat3(model.vertex[pixel]));
  int row = 0;
  int col = 0;
  if (!projection.pixelOf(moved, row, col)) return;
  scratch.moved_pixel[pixel] = row * projection.cols + col;
  scratch.moved_range[pixel] = norm(moved);
}

}  // namespace

void fuseSphericalModel(const SphericalImage& model, const ScanImage& scan, const SphericalProjection& projection,
                        const Eigen::Isometry3d& model_from_scan, const ModelFusion& fusion,
                        SphericalFusionScratch& scratch, SphericalImage& fused) {
  const Rigid3f scan_from_model = toRigid3f(model_from_scan.inverse());
  const uint32_t pixels = static_cast<uint32_t>(model.pixelCount());
  const SphericalImage& observed = scan.image;
  // Calls offer(pixel, range, stamp, source) for the model point at `pixel`, moved (moveModelPoint()
  // must have run), and for the scan point at `pixel` if it joins the model.
  const auto offersFrom = [&](size_t pixel, const auto& offer) {
    const int32_t target = scratch.moved_pixel[pixel];
    if (target >= 0) offer(target, scratch.moved_range[pixel], model.stamp[pixel], static_cast<uint32_t>(pixel));
    if (joinsModel(scan.label[pixel], toFloat3(observed.normal[pixel]))) {
      offer(pixel, observed.range[pixel], observed.stamp[pixel], scanSource(static_cast<uint32_t>(pixel), pixels));
    }
  };

  ClosestWins& closest = scratch.closest;
  ClosestWins& oldest = scratch.oldest;
  // Round 1 moves each model point once; round 2 reuses where it landed.
  parallelFor(pixels, [&](size_t pixel) {
    moveModelPoint(model, pixel, scan_from_model, projection, fusion, scratch);
    offersFrom(pixel,
               [&](size_t target, float range, float, uint32_t source) { closest.offer(target, range, source); });
  });
  parallelFor(pixels, [&](size_t pixel) {
    offersFrom(pixel, [&](size_t target, float range, float observed_at, uint32_t source) {
      if (onClosestSurface(range, closest.range(target), fusion.same_surface_distance)) {
        oldest.offerKey(target, oldestWinsKey(observed_at, source));
      }
    });
  });

  // Taking each pixel's winners empties both rounds for the next update.
  parallelFor(pixels, [&](size_t pixel) {
    closest.take(pixel);
    const ClosestKey winner = oldest.take(pixel);
    if (winner == kNoClosestKey) {
      fused.range[pixel] = 0.0f;
      fused.normal[pixel].setZero();
      return;
    }
    const uint32_t source = closestWinsSource(winner);
    if (isScanSource(source, pixels)) {
      const size_t from = source - pixels;
      fused.vertex[pixel] = observed.vertex[from];
      fused.normal[pixel] = observed.normal[from];
      fused.range[pixel] = observed.range[from];
      fused.stamp[pixel] = observed.stamp[from];
    } else {
      fused.vertex[pixel] = toVec3f(scan_from_model.apply(toFloat3(model.vertex[source])));
      fused.normal[pixel] = toVec3f(scan_from_model.rotate(toFloat3(model.normal[source])));
      fused.range[pixel] = scratch.moved_range[source];
      fused.stamp[pixel] = model.stamp[source];
    }
  });
}

void fuseGroundModel(const BevImage& model, const BevImage& scan_ground, const BevProjection& projection,
                     const Eigen::Isometry3d& model_from_scan, const ModelFusion& fusion, BevImage& fused) {
  const Rigid3f scan_from_model = toRigid3f(model_from_scan.inverse());
  // Model points move in parallel, each into its own entry (cell -1: not offered); the offered ones are
  // then gathered in order and the scan's points follow, so the offers keep the order of their sources,
  // which gives the map's slots.
  std::vector<GroundOffer> moved(model.size());
  parallelFor(model.size(), [&](size_t point) {
    if (!isCurrent(fusion.now, model.stamp[point], fusion.time_window)) return;
    const Float3 position = scan_from_model.apply(toFloat3(model.vertex[point]));
    int row = 0;
    int col = 0;
    if (!projection.cellOf(position, row, col)) return;
    moved[point] = {row * projection.cols + col, toVec3f(position), model.stamp[point], static_cast<uint32_t>(point)};
  });
  std::vector<int32_t> offered;
  parallelSelect(model.size(), [&](size_t point) { return moved[point].cell >= 0; }, offered);
  const uint32_t model_points = static_cast<uint32_t>(model.size());
  std::vector<GroundOffer> offers(offered.size() + scan_ground.size());
  parallelFor(offers.size(), [&](size_t i) {
    if (i < offered.size()) {
      offers[i] = moved[offered[i]];
      return;
    }
    const size_t point = i - offered.size();
    offers[i] = {scan_ground.cell[point], scan_ground.vertex[point], scan_ground.stamp[point],
                 model_points + static_cast<uint32_t>(point)};
  });
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
