// Motion compensation of the projected scan on the GPU, in place: one thread per pixel, the per-pixel math
// of the CPU backend (redeskewPixel(), deskew.hpp; turnedPixelMoved() for a scan a gyro's rotation turned).
#include "core/cuda/kernels.hpp"
#include "core/cuda/launch.cuh"

namespace elo::cuda {

namespace {

__global__ void deskewPixels(DeviceScan scan, SweepVelocity applied, SweepVelocity velocity) {
  const int pixel = globalThread();
  if (pixel >= scan.pixels() || !scan.occupied(pixel)) return;
  redeskewPixel(applied, velocity, scan.measured[pixel], scan.times[pixel], scan.vertices[pixel], scan.ranges[pixel],
                scan.normals[pixel]);
}

__global__ void moveTurnedPixels(DeviceScan scan, SweepVelocity applied, SweepVelocity velocity) {
  const int pixel = globalThread();
  if (pixel >= scan.pixels() || !scan.occupied(pixel)) return;
  const Float3 moved = turnedPixelMoved(applied, velocity, scan.times[pixel], scan.vertices[pixel]);
  scan.vertices[pixel] = moved;
  scan.ranges[pixel] = norm(moved);
}

}  // namespace

void deskewScan(const DeviceScan& scan, const SweepVelocity& applied, const SweepVelocity& velocity,
                cudaStream_t stream) {
  deskewPixels<<<blocksFor(scan.pixels()), kThreads, 0, stream>>>(scan, applied, velocity);
  checkLaunch("deskewPixels");
}

void deskewTurnedScan(const DeviceScan& scan, const SweepVelocity& applied, const SweepVelocity& velocity,
                      cudaStream_t stream) {
  moveTurnedPixels<<<blocksFor(scan.pixels()), kThreads, 0, stream>>>(scan, applied, velocity);
  checkLaunch("moveTurnedPixels");
}

}  // namespace elo::cuda
