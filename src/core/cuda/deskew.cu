// Motion compensation of the projected scan on the GPU, in place: one thread per pixel, the per-pixel math
// of the CPU backend (redeskewPixel(), deskew.hpp), turned at the velocity's rate or by the gyro's rotation.
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

__global__ void deskewPixelsWithGyro(DeviceScan scan, SweepRotation rotation, SweepVelocity velocity) {
  const int pixel = globalThread();
  if (pixel >= scan.pixels() || !scan.occupied(pixel)) return;
  redeskewPixel(rotation, velocity, scan.measured[pixel], scan.times[pixel], scan.vertices[pixel], scan.ranges[pixel]);
}

}  // namespace

void deskewScan(const DeviceScan& scan, const SweepVelocity& applied, const SweepVelocity& velocity,
                cudaStream_t stream) {
  deskewPixels<<<blocksFor(scan.pixels()), kThreads, 0, stream>>>(scan, applied, velocity);
  checkLaunch("deskewPixels");
}

void deskewScan(const DeviceScan& scan, const SweepRotation& rotation, const SweepVelocity& velocity,
                cudaStream_t stream) {
  deskewPixelsWithGyro<<<blocksFor(scan.pixels()), kThreads, 0, stream>>>(scan, rotation, velocity);
  checkLaunch("deskewPixelsWithGyro");
}

}  // namespace elo::cuda
