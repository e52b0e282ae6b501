// Sec. III-B.3-4 on the GPU: one thread per pixel runs pixelNormal() of normals.hpp, whose agreement with
// the CPU backend's vectorised estimator a CPU test checks. Then the non-ground pixels with a normal are
// listed in pixel order, as the CPU backend lists them, for the registration.
#include "core/cuda/kernels.hpp"
#include "core/cuda/launch.cuh"

namespace elo::cuda {

namespace {

// Reads vertices and labels only, and writes its own pixel's normal: no thread reads what another writes.
__global__ void pixelNormals(DeviceScan scan, NormalParams params, int* registration_flags) {
  const int pixel = globalThread();
  if (pixel >= scan.pixels()) return;
  const bool usable = scan.usable(pixel);
  const Float3 normal = usable ? pixelNormal(scan, pixel / scan.cols, pixel % scan.cols, params)
                               : Float3{0.0f, 0.0f, 0.0f};
  scan.normals[pixel] = normal;
  registration_flags[pixel] = usable && !isZero(normal) ? 1 : 0;
}

__global__ void listFlagged(int items, FlaggedList list) {
  const int i = globalThread();
  if (i >= items) return;
  if (list.flags[i] != 0) list.items[list.offsets[i]] = i;
  if (i == items - 1) *list.count = list.offsets[i] + list.flags[i];
}

}  // namespace

void estimateNormals(const DeviceScan& scan, const NormalParams& params, const FlaggedList& registration_pixels,
                     cudaStream_t stream) {
  const int pixels = scan.pixels();
  pixelNormals<<<blocksFor(pixels), kThreads, 0, stream>>>(scan, params, registration_pixels.flags);
  checkLaunch("pixelNormals");
  exclusiveSum(registration_pixels.flags, registration_pixels.offsets, pixels, registration_pixels.scan_scratch,
               registration_pixels.scan_scratch_bytes, stream);
  listFlagged<<<blocksFor(pixels), kThreads, 0, stream>>>(pixels, registration_pixels);
  checkLaunch("listFlagged");
}

}  // namespace elo::cuda
