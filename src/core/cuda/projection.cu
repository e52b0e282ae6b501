// Sec. III-B.1 on the GPU: every point, deskewed, offers itself to its pixel with an atomicMin of its
// closest-wins key, then every pixel takes its winner. The per-point math is scanPointPixel()
// (scan_projection.hpp), the same as the CPU backend's, so both fill the same pixels with the same points.
#include "core/common/scan_projection.hpp"
#include "core/cuda/kernels.hpp"
#include "core/cuda/launch.cuh"

namespace elo::cuda {

namespace {

// How the kernels place a cloud point: the same for the offer and for the winner.
struct PointPlacement {
  UploadedCloud cloud;
  SphericalProjection projection;
  ElevationCorrection correction;
  SweepDeskew deskew;
  const int* ring_rows;
  int ring_count;

  __device__ bool place(int i, ScanPoint& point) const {
    const int ring = cloud.rings != nullptr ? static_cast<int>(cloud.rings[i]) : kNoRing;
    return scanPointPixel(projection, correction, deskew, i, cloud.points[i], ring, ring_rows, ring_count, point);
  }
};

__global__ void offerPoints(PointPlacement placement, ClosestKey* pixel_keys) {
  const int i = globalThread();
  if (i >= placement.cloud.count) return;
  ScanPoint point;
  if (!placement.place(i, point)) return;
  atomicMin(&pixel_keys[point.pixel], closestWinsKey(norm(point.vertex), static_cast<uint32_t>(i)));
}

__global__ void takeWinners(const ClosestKey* pixel_keys, PointPlacement placement, float stamp, DeviceScan scan,
                            int* occupied) {
  const int pixel = globalThread();
  bool taken = false;
  if (pixel < scan.pixels()) {
    scan.normals[pixel] = Float3{0.0f, 0.0f, 0.0f};
    const ClosestKey key = pixel_keys[pixel];
    if (key == kNoClosestKey) {
      scan.ranges[pixel] = 0.0f;
      scan.point_indices[pixel] = -1;
      scan.labels[pixel] = PixelLabel::empty;
    } else {
      const uint32_t index = closestWinsSource(key);
      ScanPoint point;
      scanPointVertex(placement.correction, placement.deskew, static_cast<int>(index), placement.cloud.points[index],
                      point);
      scan.vertices[pixel] = point.vertex;
      scan.ranges[pixel] = norm(point.vertex);
      scan.stamps[pixel] = stamp;
      scan.measured[pixel] = point.measured;
      scan.times[pixel] = point.time;
      scan.point_indices[pixel] = static_cast<int32_t>(index);
      scan.labels[pixel] = PixelLabel::nonground;
      taken = true;
    }
  }
  // Every thread of the block reaches this (no early return above). One atomic per block.
  const int block_count = __syncthreads_count(taken);
  if (threadIdx.x == 0 && block_count > 0) atomicAdd(occupied, block_count);
}

}  // namespace

void projectScan(const UploadedCloud& cloud, const SphericalProjection& projection,
                 const ElevationCorrection& correction, const SweepDeskew& deskew, const int* ring_rows,
                 int ring_count, float stamp, ClosestKey* pixel_keys, const DeviceScan& scan, int* occupied,
                 cudaStream_t stream) {
  const PointPlacement placement{cloud, projection, correction, deskew, ring_rows, ring_count};
  check(cudaMemsetAsync(pixel_keys, 0xff, sizeof(ClosestKey) * scan.pixels(), stream), "clearing the pixel keys");
  check(cudaMemsetAsync(occupied, 0, sizeof(int), stream), "clearing the occupied count");
  if (cloud.count > 0) {
    offerPoints<<<blocksFor(cloud.count), kThreads, 0, stream>>>(placement, pixel_keys);
    checkLaunch("offerPoints");
  }
  takeWinners<<<blocksFor(scan.pixels()), kThreads, 0, stream>>>(pixel_keys, placement, stamp, scan, occupied);
  checkLaunch("takeWinners");
}

}  // namespace elo::cuda
