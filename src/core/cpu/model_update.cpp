// Sec. III-D: the model update. The model lives in the frame of the latest scan: each frame, every model
// point moves into the new frame and is re-projected; where the scan also has a point the one closer to
// the sensor stays, unless both lie on one surface, when the older stays; where it has none the model's
// stays, and points older than tau_w go. Only three 2D maps are kept (vertex and normal maps of the SRI,
// vertex map of the BEV), so memory never grows. The per-point rules are shared with the CUDA backend
// (model_update.hpp).
#include <algorithm>
#include <vector>

#include "core/common/eigen_interop.hpp"
#include "core/common/model_update.hpp"
#include "core/cpu/parallel.hpp"
#include "core/cpu/stages.hpp"

namespace elo::cpu {

void SphericalFusionScratch::resize(size_t pixels) {
  closest.resize(pixels);
  oldest.resize(pixels);
  moved.resize(pixels);
  scan_key.resize(pixels);
}

namespace {

// Model pixel `pixel` moved into the scan's frame: where it lands, pixel -1 when it is not offered (empty,
// no normal, expired, or out of the image).
SphericalFusionScratch::Moved moveModelPoint(const SphericalImage& model, size_t pixel, const Rigid3f& scan_from_model,
                                             const SphericalProjection& projection, const ModelFusion& fusion) {
  constexpr SphericalFusionScratch::Moved kNotOffered{-1, 0.0f};
  if (!model.occupied(pixel) || !model.hasNormal(pixel)) return kNotOffered;
  if (!isCurrent(fusion.now, model.stamp[pixel], fusion.time_window)) return kNotOffered;
  const Float3 moved = scan_from_model.apply(toFloat3(model.vertex[pixel]));
  int row = 0;
  int col = 0;
  if (!projection.pixelOf(moved, row, col)) return kNotOffered;
  return {row * projection.cols + col, norm(moved)};
}

ImagePixel pixelOf(const SphericalImage& image, size_t pixel) {
  return {toFloat3(image.vertex[pixel]), toFloat3(image.normal[pixel]), image.range[pixel], image.stamp[pixel]};
}

}  // namespace

void fuseSphericalModel(const SphericalImage& model, const ScanImage& scan, const SphericalProjection& projection,
                        const Eigen::Isometry3d& model_from_scan, const ModelFusion& fusion,
                        SphericalFusionScratch& scratch, SphericalImage& fused) {
  const Rigid3f scan_from_model = toRigid3f(model_from_scan.inverse());
  const uint32_t pixels = static_cast<uint32_t>(model.pixelCount());
  const SphericalImage& observed = scan.image;
  ClosestWins& closest = scratch.closest;
  ClosestWins& oldest = scratch.oldest;
  std::vector<SphericalFusionScratch::Moved>& moved = scratch.moved;
  std::vector<ClosestKey>& scan_key = scratch.scan_key;
  // A pixel's closest key over all its offers: the model's (closest) and the scan's own.
  const auto closestKey = [&](size_t pixel) { return std::min(closest.key(pixel), scan_key[pixel]); };

  closest.setSingleWriter(runsAlone());
  oldest.setSingleWriter(runsAlone());
  // Round 1 moves each model point once and offers it; each scan pixel notes its own offer.
  parallelFor(pixels, [&](size_t pixel) {
    moved[pixel] = moveModelPoint(model, pixel, scan_from_model, projection, fusion);
    if (moved[pixel].pixel >= 0) closest.offer(moved[pixel].pixel, moved[pixel].range, static_cast<uint32_t>(pixel));
    scan_key[pixel] = joinsModel(scan.label[pixel], toFloat3(observed.normal[pixel]))
                          ? closestWinsKey(observed.range[pixel], scanSource(static_cast<uint32_t>(pixel), pixels))
                          : kNoClosestKey;
  });
  // Round 2 reuses where each model point landed.
  parallelFor(pixels, [&](size_t pixel) {
    const SphericalFusionScratch::Moved& from = moved[pixel];
    if (from.pixel < 0) return;
    if (onClosestSurface(from.range, closestWinsRange(closestKey(from.pixel)), fusion.same_surface_distance)) {
      oldest.offerKey(from.pixel, oldestWinsKey(model.stamp[pixel], static_cast<uint32_t>(pixel)));
    }
  });

  // Each pixel's winner: the oldest model offer on the closest surface, or the scan's own if it is on
  // that surface and older (or of the same age and ranked first by the hash). Taking the keys empties both rounds
  // for the next update.
  parallelFor(pixels, [&](size_t pixel) {
    const ClosestKey nearest = closestKey(pixel);
    closest.take(pixel);
    ClosestKey winner = oldest.take(pixel);
    if (scan_key[pixel] != kNoClosestKey &&
        onClosestSurface(observed.range[pixel], closestWinsRange(nearest), fusion.same_surface_distance)) {
      winner = std::min(winner, oldestWinsKey(observed.stamp[pixel], scanSource(static_cast<uint32_t>(pixel), pixels)));
    }
    if (winner == kNoClosestKey) {
      fused.range[pixel] = 0.0f;
      fused.normal[pixel].setZero();
      return;
    }
    const ImagePixel taken = fusedPixel(oldestWinsSource(winner), pixels, scan_from_model,
                                        [&](uint32_t from) { return pixelOf(observed, from); },
                                        [&](uint32_t from) { return pixelOf(model, from); });
    fused.vertex[pixel] = toVec3f(taken.vertex);
    fused.normal[pixel] = toVec3f(taken.normal);
    fused.range[pixel] = taken.range;
    fused.stamp[pixel] = taken.stamp;
  });
}

void fuseGroundModel(const BevImage& model, const BevImage& scan_ground, const BevProjection& projection,
                     const Eigen::Isometry3d& model_from_scan, const ModelFusion& fusion, GroundMapScratch& scratch,
                     BevImage& fused) {
  const Rigid3f scan_from_model = toRigid3f(model_from_scan.inverse());
  // One offer per source, in the order of the sources: each model point moved (cell -1 when it is not
  // offered), then the scan's points. The slots of the map follow that order.
  const uint32_t model_points = static_cast<uint32_t>(model.size());
  std::vector<GroundOffer>& offers = scratch.offers;
  offers.resize(model.size() + scan_ground.size());
  parallelFor(offers.size(), [&](size_t i) {
    GroundOffer& offer = offers[i];
    if (i >= model_points) {
      const size_t point = i - model_points;
      offer = {scan_ground.cell[point], scan_ground.vertex[point], scan_ground.stamp[point],
               model_points + static_cast<uint32_t>(point)};
      return;
    }
    offer.cell = -1;
    if (!isCurrent(fusion.now, model.stamp[i], fusion.time_window)) return;
    const Float3 position = scan_from_model.apply(toFloat3(model.vertex[i]));
    int row = 0;
    int col = 0;
    if (!projection.cellOf(position, row, col)) return;
    offer = {row * projection.cols + col, toVec3f(position), model.stamp[i], static_cast<uint32_t>(i)};
  });
  fillGroundMap(fusion.same_surface_distance, scratch, fused);
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
