// Sec. III-C.1 on the GPU: one thread walks one column of the range image (segmentColumn() of
// ground.hpp, the CPU backend's code). Adjacent threads read adjacent columns of each row: coalesced.
#include "core/cuda/kernels.hpp"
#include "core/cuda/launch.cuh"

namespace elo::cuda {

namespace {

__global__ void segmentColumns(DeviceScan scan, GroundBand band) {
  const int col = globalThread();
  if (col >= scan.cols) return;
  segmentColumn(scan, col, band);
}

__global__ void labelOccupiedNonground(DeviceScan scan) {
  const int pixel = globalThread();
  if (pixel < scan.pixels() && scan.occupied(pixel)) scan.labels[pixel] = PixelLabel::nonground;
}

}  // namespace

void segmentGround(const DeviceScan& scan, const GroundBand& band, cudaStream_t stream) {
  segmentColumns<<<blocksFor(scan.cols), kThreads, 0, stream>>>(scan, band);
  checkLaunch("segmentColumns");
}

void labelAllNonground(const DeviceScan& scan, cudaStream_t stream) {
  labelOccupiedNonground<<<blocksFor(scan.pixels()), kThreads, 0, stream>>>(scan);
  checkLaunch("labelOccupiedNonground");
}

}  // namespace elo::cuda
