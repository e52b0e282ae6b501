// Sec. III-D on the GPU, the non-ground model: every current model pixel moves into the scan's frame and
// offers itself to the pixel it projects to, every scan pixel that joins the model offers itself to its
// own pixel, and each pixel takes the closest offer (model_update.hpp, the CPU backend's rules). The
// fused image is written to a second buffer, so no thread reads what another writes.
#include "core/common/model_update.hpp"
#include "core/cuda/kernels.hpp"
#include "core/cuda/launch.cuh"

namespace elo::cuda {

namespace {

__global__ void offerSphericalSources(DeviceModelImage model, DeviceScan scan, SphericalProjection projection,
                                      Rigid3f scan_from_model, float now, float time_window, ClosestKey* pixel_keys) {
  const int pixel = globalThread();
  if (pixel >= model.pixels()) return;
  const uint32_t pixels = static_cast<uint32_t>(model.pixels());
  if (model.matchable(pixel) && isCurrent(now, model.stamps[pixel], time_window)) {
    const Float3 moved = scan_from_model.apply(model.vertices[pixel]);
    int row = 0;
    int col = 0;
    if (projection.pixelOf(moved, row, col)) {
      atomicMin(&pixel_keys[row * projection.cols + col], closestWinsKey(norm(moved), static_cast<uint32_t>(pixel)));
    }
  }
  if (joinsModel(scan.labels[pixel], scan.normals[pixel])) {
    atomicMin(&pixel_keys[pixel], closestWinsKey(scan.ranges[pixel], scanSource(static_cast<uint32_t>(pixel), pixels)));
  }
}

__global__ void takeFusedWinners(const ClosestKey* pixel_keys, DeviceModelImage model, DeviceScan scan,
                                 Rigid3f scan_from_model, DeviceModelImage fused) {
  const int pixel = globalThread();
  if (pixel >= fused.pixels()) return;
  const ClosestKey key = pixel_keys[pixel];
  if (key == kNoClosestKey) {
    fused.ranges[pixel] = 0.0f;
    fused.normals[pixel] = Float3{0.0f, 0.0f, 0.0f};
    return;
  }
  const uint32_t pixels = static_cast<uint32_t>(fused.pixels());
  const uint32_t source = closestWinsSource(key);
  if (isScanSource(source, pixels)) {
    const uint32_t from = source - pixels;
    fused.vertices[pixel] = scan.vertices[from];
    fused.normals[pixel] = scan.normals[from];
    fused.ranges[pixel] = scan.ranges[from];
    fused.stamps[pixel] = scan.stamps[from];
  } else {
    const Float3 moved = scan_from_model.apply(model.vertices[source]);
    fused.vertices[pixel] = moved;
    fused.normals[pixel] = scan_from_model.rotate(model.normals[source]);
    fused.ranges[pixel] = norm(moved);
    fused.stamps[pixel] = model.stamps[source];
  }
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
                        const Rigid3f& scan_from_model, float now, float time_window, ClosestKey* pixel_keys,
                        const DeviceModelImage& fused, cudaStream_t stream) {
  const int pixels = model.pixels();
  check(cudaMemsetAsync(pixel_keys, 0xff, sizeof(ClosestKey) * pixels, stream), "clearing the pixel keys");
  offerSphericalSources<<<blocksFor(pixels), kThreads, 0, stream>>>(model, scan, projection, scan_from_model, now,
                                                                    time_window, pixel_keys);
  checkLaunch("offerSphericalSources");
  takeFusedWinners<<<blocksFor(pixels), kThreads, 0, stream>>>(pixel_keys, model, scan, scan_from_model, fused);
  checkLaunch("takeFusedWinners");
}

void copyScanToModel(const DeviceScan& scan, const DeviceModelImage& model, cudaStream_t stream) {
  copyJoiningPixels<<<blocksFor(scan.pixels()), kThreads, 0, stream>>>(scan, model);
  checkLaunch("copyJoiningPixels");
}

}  // namespace elo::cuda
