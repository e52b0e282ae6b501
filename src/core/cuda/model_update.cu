// Sec. III-D on the GPU, the non-ground model: every current model pixel moves into the scan's frame and
// offers itself to the pixel it projects to, every scan pixel that joins the model offers itself to its
// own pixel, and each pixel takes the oldest offer on its closest surface (two rounds of atomicMin, the
// rules of model_update.hpp that the CPU backend applies too). The fused image is written to a second
// buffer, so no thread reads what another writes. Three launches; the last one returns both rounds' keys
// to "none" for the next update, which so needs no clearing of its own.
#include "core/common/model_update.hpp"
#include "core/cuda/kernels.hpp"
#include "core/cuda/launch.cuh"

namespace elo::cuda {

namespace {

// The offers of thread `pixel`: its model point, moved, and its scan point, each as (target pixel, range,
// stamp, source) to `offer`.
template <typename Offer>
__device__ void forEachOffer(int pixel, const DeviceModelImage& model, const DeviceScan& scan,
                             const SphericalProjection& projection, const Rigid3f& scan_from_model,
                             const ModelFusion& fusion, Offer offer) {
  const uint32_t pixels = static_cast<uint32_t>(model.pixels());
  if (model.matchable(pixel) && isCurrent(fusion.now, model.stamps[pixel], fusion.time_window)) {
    const Float3 moved = scan_from_model.apply(model.vertices[pixel]);
    int row = 0;
    int col = 0;
    if (projection.pixelOf(moved, row, col)) {
      offer(row * projection.cols + col, norm(moved), model.stamps[pixel], static_cast<uint32_t>(pixel));
    }
  }
  if (joinsModel(scan.labels[pixel], scan.normals[pixel])) {
    offer(pixel, scan.ranges[pixel], scan.stamps[pixel], scanSource(static_cast<uint32_t>(pixel), pixels));
  }
}

__global__ void offerClosest(DeviceModelImage model, DeviceScan scan, SphericalProjection projection,
                             Rigid3f scan_from_model, ModelFusion fusion, ClosestKey* closest_keys) {
  const int pixel = globalThread();
  if (pixel >= model.pixels()) return;
  forEachOffer(pixel, model, scan, projection, scan_from_model, fusion,
               [&](int target, float range, float, uint32_t source) {
                 atomicMin(&closest_keys[target], closestWinsKey(range, source));
               });
}

__global__ void offerOldestOnClosestSurface(DeviceModelImage model, DeviceScan scan, SphericalProjection projection,
                                            Rigid3f scan_from_model, ModelFusion fusion,
                                            const ClosestKey* closest_keys, ClosestKey* surface_keys) {
  const int pixel = globalThread();
  if (pixel >= model.pixels()) return;
  forEachOffer(pixel, model, scan, projection, scan_from_model, fusion,
               [&](int target, float range, float observed_at, uint32_t source) {
                 if (onClosestSurface(range, closestWinsRange(closest_keys[target]), fusion.same_surface_distance)) {
                   atomicMin(&surface_keys[target], oldestWinsKey(observed_at, source));
                 }
               });
}

// Both rounds are over: each pixel's keys are read here by its own thread alone, which clears them.
__global__ void takeFusedWinners(ClosestKey* closest_keys, ClosestKey* surface_keys, DeviceModelImage model,
                                 DeviceScan scan, Rigid3f scan_from_model, DeviceModelImage fused) {
  const int pixel = globalThread();
  if (pixel >= fused.pixels()) return;
  const ClosestKey key = surface_keys[pixel];
  closest_keys[pixel] = kNoClosestKey;
  surface_keys[pixel] = kNoClosestKey;
  if (key == kNoClosestKey) {
    fused.ranges[pixel] = 0.0f;
    fused.normals[pixel] = Float3{0.0f, 0.0f, 0.0f};
    return;
  }
  const ImagePixel taken = fusedPixel(
      oldestWinsSource(key), static_cast<uint32_t>(fused.pixels()), scan_from_model,
      [&](uint32_t from) { return ImagePixel{scan.vertices[from], scan.normals[from], scan.ranges[from], scan.stamps[from]}; },
      [&](uint32_t from) { return ImagePixel{model.vertices[from], model.normals[from], 0.0f, model.stamps[from]}; });
  fused.vertices[pixel] = taken.vertex;
  fused.normals[pixel] = taken.normal;
  fused.ranges[pixel] = taken.range;
  fused.stamps[pixel] = taken.stamp;
}

__global__ void copyJoiningPixels(DeviceScan scan, DeviceModelImage model) {
  const int pixel = globalThread();
  if (pixel >= scan.pixels()) return;
  const bool keep = joinsModel(scan.labels[pixel], scan.normals[pixel]);
  model.ranges[pixel] = keep ? scan.ranges[pixel] : 0.0f;
  model.vertices[pixel] = scan.vertices[pixel];
  model.normals[pixel] = keep ? scan.normals[pixel] : Float3{0.0f, 0.0f, 0.0f};
  model.stamps[pixel] = scan.stamps[pixel];
}

}  // namespace

void fuseSphericalModel(const DeviceModelImage& model, const DeviceScan& scan, const SphericalProjection& projection,
                        const Rigid3f& scan_from_model, const ModelFusion& fusion, ClosestKey* closest_keys,
                        ClosestKey* surface_keys, const DeviceModelImage& fused, cudaStream_t stream) {
  const int pixels = model.pixels();
  offerClosest<<<blocksFor(pixels), kThreads, 0, stream>>>(model, scan, projection, scan_from_model, fusion,
                                                           closest_keys);
  checkLaunch("offerClosest");
  offerOldestOnClosestSurface<<<blocksFor(pixels), kThreads, 0, stream>>>(model, scan, projection, scan_from_model,
                                                                          fusion, closest_keys, surface_keys);
  checkLaunch("offerOldestOnClosestSurface");
  takeFusedWinners<<<blocksFor(pixels), kThreads, 0, stream>>>(closest_keys, surface_keys, model, scan,
                                                               scan_from_model, fused);
  checkLaunch("takeFusedWinners");
}

void copyScanToModel(const DeviceScan& scan, const DeviceModelImage& model, cudaStream_t stream) {
  copyJoiningPixels<<<blocksFor(scan.pixels()), kThreads, 0, stream>>>(scan, model);
  checkLaunch("copyJoiningPixels");
}

}  // namespace elo::cuda
