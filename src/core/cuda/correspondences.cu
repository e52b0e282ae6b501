// Sec. III-A on the GPU: the Gauss-Newton sums of both cost terms. Each thread associates its share of
// the scan points (association.hpp) and sums their point-to-plane terms (point_to_plane.hpp) in double;
// each block reduces its threads' sums in a fixed tree (warp shuffles, then the warps in order) into one
// partial; one last kernel adds the partials in block order. No atomics on floating point and a grid
// independent of the GPU: the sums are the same on every run and every GPU.
#include "core/common/point_to_plane.hpp"
#include "core/cuda/kernels.hpp"
#include "core/cuda/launch.cuh"

namespace elo::cuda {

namespace {

constexpr int kWarps = kThreads / 32;
constexpr unsigned kFullWarp = 0xffffffffu;

struct ThreadSums {
  double values[kTermValues];
  int candidates = 0;
  int inliers = 0;

  __device__ ThreadSums() {
    for (double& value : values) value = 0.0;
  }

  __device__ void add(const PointToPlane& term) {
    addToPackedSums(term, values);
    ++inliers;
  }
};

template <typename T>
__device__ T warpSum(T value) {
  for (int offset = 16; offset > 0; offset /= 2) value += __shfl_down_sync(kFullWarp, value, offset);
  return value;  // complete in lane 0
}

// Every thread of the block must call this (no early return in the kernels).
__device__ void writeBlockSums(const ThreadSums& sums, DeviceTermSums& partial) {
  __shared__ double warp_values[kWarps][kTermValues];
  __shared__ int warp_counts[kWarps][2];
  const int lane = threadIdx.x % 32;
  const int warp = threadIdx.x / 32;
#pragma unroll
  for (int v = 0; v < kTermValues; ++v) {
    const double value = warpSum(sums.values[v]);
    if (lane == 0) warp_values[warp][v] = value;
  }
  const int candidates = warpSum(sums.candidates);
  const int inliers = warpSum(sums.inliers);
  if (lane == 0) {
    warp_counts[warp][0] = candidates;
    warp_counts[warp][1] = inliers;
  }
  __syncthreads();
  const int v = threadIdx.x;
  if (v < kTermValues) {
    double total = 0.0;
    for (int w = 0; w < kWarps; ++w) total += warp_values[w][v];
    partial.values[v] = total;
  } else if (v == kTermValues) {
    int total = 0;
    for (int w = 0; w < kWarps; ++w) total += warp_counts[w][0];
    partial.candidates = total;
  } else if (v == kTermValues + 1) {
    int total = 0;
    for (int w = 0; w < kWarps; ++w) total += warp_counts[w][1];
    partial.inliers = total;
  }
}

__global__ void __launch_bounds__(kThreads) nongroundSums(LinearizeInputs in, DeviceTermSums* partials) {
  ThreadSums sums;
  const int count = *in.registration_count;
  for (int i = globalThread(); i < count; i += gridThreads()) {
    ++sums.candidates;
    const int pixel = in.registration_pixels[i];
    Float3 moved;
    int match = -1;
    if (!nongroundMatch(in.spherical, in.model, in.motion, in.scan.vertices[pixel], in.scan.normals[pixel], in.gates,
                        moved, match)) {
      continue;
    }
    sums.add(pointToPlane(moved, in.model.vertices[match], in.model.normals[match], in.kernel_scale));
  }
  writeBlockSums(sums, partials[blockIdx.x]);
}

__global__ void __launch_bounds__(kThreads) groundSums(LinearizeInputs in, DeviceTermSums* partials) {
  ThreadSums sums;
  const int count = *in.scan_ground.count;
  for (int i = globalThread(); i < count; i += gridThreads()) {
    ++sums.candidates;
    Float3 moved;
    int32_t match = -1;
    if (!groundMatch(in.bev, in.model_ground, in.motion, in.scan_ground.vertices[i], in.gates, in.patch_radius, moved,
                     match)) {
      continue;
    }
    const Float3 normal = in.model_ground_normals[match];
    if (isZero(normal)) continue;
    sums.add(pointToPlane(moved, in.model_ground.vertices[match], normal, in.kernel_scale));
  }
  writeBlockSums(sums, partials[blockIdx.x]);
}

// Block `term` adds that term's partials in block order; a term left out gets zeros.
__global__ void sumPartials(const DeviceTermSums* partials, bool nonground, bool ground, DeviceTermSums* results) {
  const int term = blockIdx.x;
  const bool summed = term == 0 ? nonground : ground;
  const DeviceTermSums* blocks = partials + term * kReductionBlocks;
  const int v = threadIdx.x;
  if (v < kTermValues) {
    double total = 0.0;
    for (int b = 0; summed && b < kReductionBlocks; ++b) total += blocks[b].values[v];
    results[term].values[v] = total;
  } else if (v == kTermValues) {
    int total = 0;
    for (int b = 0; summed && b < kReductionBlocks; ++b) total += blocks[b].candidates;
    results[term].candidates = total;
  } else if (v == kTermValues + 1) {
    int total = 0;
    for (int b = 0; summed && b < kReductionBlocks; ++b) total += blocks[b].inliers;
    results[term].inliers = total;
  }
}

}  // namespace

void linearize(const LinearizeInputs& inputs, DeviceTermSums* partials, DeviceTermSums* results, cudaStream_t stream) {
  if (inputs.nonground) {
    nongroundSums<<<kReductionBlocks, kThreads, 0, stream>>>(inputs, partials);
    checkLaunch("nongroundSums");
  }
  if (inputs.ground) {
    groundSums<<<kReductionBlocks, kThreads, 0, stream>>>(inputs, partials + kReductionBlocks);
    checkLaunch("groundSums");
  }
  static_assert(kTermValues + 2 <= 32, "one warp adds the partials of a term");
  sumPartials<<<kTerms, 32, 0, stream>>>(partials, inputs.nonground, inputs.ground, results);
  checkLaunch("sumPartials");
}

}  // namespace elo::cuda
