// Sec. III-A on the GPU: the Gauss-Newton sums of both cost terms, in one launch per iteration. Block
// (x, y) sums term y (or the one term summed) over its share of that term's points: each thread
// associates its points (association.hpp) and sums their point-to-plane terms (point_to_plane.hpp) in
// double; the block reduces its threads' sums in a fixed tree (warp shuffles, then the warps in order)
// into one partial per row. The last block to finish adds every term's partials, in a fixed tree again,
// and writes the totals straight into the host's pinned memory: no second kernel and no copy. The
// grid is fixed (kReductionBlocks per term) and no floating-point value goes through an atomic, so the
// sums are the same on every run and every GPU.
// cuda::atomic_ref comes with CUDA 11.6, on float with CUDA 12.0 (JetPack 5 has 11.4). Before 12, or
// with ELO_CUDA_LEGACY_FALLBACKS (which lets a GPU machine with a newer toolkit test them), the accesses
// below are volatile ones and fences, as CUDA's memory model guide gives them (docs/platforms.md).
#if __CUDACC_VER_MAJOR__ >= 12 && !defined(ELO_CUDA_LEGACY_FALLBACKS)
#define ELO_CUDA_ATOMIC_REF 1
#include <cuda/atomic>
#endif

#include "core/common/point_to_plane.hpp"
#include "core/cuda/kernels.hpp"
#include "core/cuda/launch.cuh"

namespace elo::cuda {

namespace {

constexpr int kWarps = kThreads / 32;
constexpr unsigned kFullWarp = 0xffffffffu;
constexpr int kNonground = 0;  // term indices, as kTerms counts them
constexpr int kGround = 1;
constexpr int kPartialsPerLane = kReductionBlocks / 32;
constexpr int kTotalRows = kTerms * kPartialRows;
constexpr int kRowsPerWarp = (kTotalRows + kWarps - 1) / kWarps;
static_assert(kReductionBlocks % 32 == 0, "a warp adds a row of partials, every lane as many");
static_assert(kPartialRows <= kThreads, "a block writes each of its partial's rows with one thread");

#ifdef ELO_CUDA_ATOMIC_REF
__device__ float relaxedLoad(float& value) {
  return ::cuda::atomic_ref<float, ::cuda::thread_scope_device>(value).load(::cuda::memory_order_relaxed);
}

__device__ void relaxedStore(float& target, float value) {
  ::cuda::atomic_ref<float, ::cuda::thread_scope_device>(target).store(value, ::cuda::memory_order_relaxed);
}

__device__ unsigned acquireLoad(unsigned& value) {
  return ::cuda::atomic_ref<unsigned, ::cuda::thread_scope_device>(value).load(::cuda::memory_order_acquire);
}

__device__ void releaseStore(unsigned& target, unsigned value) {
  ::cuda::atomic_ref<unsigned, ::cuda::thread_scope_device>(target).store(value, ::cuda::memory_order_release);
}
#else
// An aligned 32-bit volatile access is one untorn load or store that bypasses no other thread's write
// (ld.volatile / st.volatile): a relaxed atomic. The fence after the acquiring load keeps every later
// read after it; the fence before the releasing store keeps every earlier write before it, device-wide.
__device__ float relaxedLoad(float& value) { return *const_cast<volatile float*>(&value); }

__device__ void relaxedStore(float& target, float value) { *const_cast<volatile float*>(&target) = value; }

__device__ unsigned acquireLoad(unsigned& value) {
  const unsigned loaded = *const_cast<volatile unsigned*>(&value);
  __threadfence();
  return loaded;
}

__device__ void releaseStore(unsigned& target, unsigned value) {
  __threadfence();
  *const_cast<volatile unsigned*>(&target) = value;
}
#endif

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

// Row `row` of term `term`'s partials: one value per block of the term.
__device__ double* partialRow(double* partials, int term, int row) {
  return partials + (term * kPartialRows + row) * kReductionBlocks;
}

__device__ bool summed(const LinearizeInputs& in, int term) { return term == kNonground ? in.nonground : in.ground; }

// The term this block sums: row y of the grid when both are summed, else the one that is.
__device__ int termOfBlock(const LinearizeInputs& in) {
  if (gridDim.y == kTerms) return static_cast<int>(blockIdx.y);
  return in.nonground ? kNonground : kGround;
}

__device__ void addNongroundTerms(const LinearizeInputs& in, ThreadSums& sums) {
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
    sums.add(nongroundTerm(moved, in.model.vertices[match], in.model.normals[match], in.scan.ranges[pixel],
                           in.kernel_scale, in.near_weight_range));
  }
}

// The normal of model ground point `match`, fitted on first use and cached for the model's lifetime (its
// epoch), as the CPU backend's cache does: a scan matches a small part of the model's ground points, and
// fitting all of them at every update cost more than the sums. The fit is groundNormal() of the same map
// whoever runs it, so every thread gets the same bits; two threads fitting one point at once store the
// same values. The normal is stored before its epoch is released, and read only after the epoch is
// acquired.
__device__ Float3 cachedGroundNormal(const LinearizeInputs& in, int32_t match) {
  const GroundNormalCache& cache = in.ground_normals;
  unsigned& epoch = cache.epochs[match];
  float* stored = &cache.normals[match].x;
  if (acquireLoad(epoch) == cache.epoch) {
    return {relaxedLoad(stored[0]), relaxedLoad(stored[1]), relaxedLoad(stored[2])};
  }
  const Float3 normal = groundNormal(in.model_ground, in.bev, match, in.normal_neighbours, in.patch_radius);
  relaxedStore(stored[0], normal.x);
  relaxedStore(stored[1], normal.y);
  relaxedStore(stored[2], normal.z);
  releaseStore(epoch, cache.epoch);
  return normal;
}

__device__ void addGroundTerms(const LinearizeInputs& in, ThreadSums& sums) {
  const int count = *in.scan_ground.count;
  for (int i = globalThread(); i < count; i += gridThreads()) {
    ++sums.candidates;
    Float3 moved;
    int32_t match = -1;
    if (!groundMatch(in.bev, in.model_ground, in.motion, in.scan_ground.vertices[i], in.gates, in.patch_radius, moved,
                     match)) {
      continue;
    }
    const Float3 normal = cachedGroundNormal(in, match);
    if (isZero(normal)) continue;
    sums.add(pointToPlane(moved, in.model_ground.vertices[match], normal, in.kernel_scale));
  }
}

// Every thread of the block must call this (no early return in the kernel). The counts go in as
// doubles, exact far beyond any point count, so that the last block adds every row alike.
__device__ void writeBlockSums(const ThreadSums& sums, double* partials, int term) {
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
  const int row = threadIdx.x;
  if (row < kTermValues) {
    double total = 0.0;
    for (int w = 0; w < kWarps; ++w) total += warp_values[w][row];
    partialRow(partials, term, row)[blockIdx.x] = total;
  } else if (row < kPartialRows) {
    int total = 0;
    for (int w = 0; w < kWarps; ++w) total += warp_counts[w][row - kTermValues];
    partialRow(partials, term, row)[blockIdx.x] = total;
  }
}

// Whether this block is the last of the launch to get here; every block's partials are then visible to
// it. The count wraps back to 0 with the last block's increment (atomicInc), ready for the next launch.
// Every thread of the block must call this.
__device__ bool lastBlockToFinish(unsigned* finished_blocks) {
  __shared__ bool last;
  __threadfence();  // this thread's partial reaches the whole GPU before the count says it is there
  __syncthreads();
  if (threadIdx.x == 0) {
    const unsigned blocks = gridDim.x * gridDim.y;
    last = atomicInc(finished_blocks, blocks - 1) == blocks - 1;
    __threadfence();  // the partials the block reads next are read after every block's increment
  }
  __syncthreads();
  return last;
}

__device__ void writeTotal(int row, double total, DeviceTermSums& result) {
  if (row < kTermValues) {
    result.values[row] = total;
  } else if (row == kTermValues) {
    result.candidates = static_cast<int>(total);
  } else {
    result.inliers = static_cast<int>(total);
  }
}

// In the last block: the totals of every row of both terms. Warp w adds rows w, w + kWarps, ...; lane l
// the partials of blocks l, l + 32, ... in that order, then the lanes in a fixed tree. The partials are
// read from L2 (__ldcg), where the other blocks wrote them, all of a warp's rows at once so that it waits
// for L2 only once; a row past the last reads the last again and is dropped. A term not summed gets zeros.
__device__ void writeTotals(const LinearizeInputs& in, const double* partials, DeviceTermSums* results) {
  const int lane = threadIdx.x % 32;
  const int warp = threadIdx.x / 32;
  double loaded[kRowsPerWarp][kPartialsPerLane];
#pragma unroll
  for (int k = 0; k < kRowsPerWarp; ++k) {
    const double* row = partials + min(warp + k * kWarps, kTotalRows - 1) * kReductionBlocks;
#pragma unroll
    for (int b = 0; b < kPartialsPerLane; ++b) loaded[k][b] = __ldcg(row + lane + 32 * b);
  }
  double totals[kRowsPerWarp];  // complete in lane 0
#pragma unroll
  for (int k = 0; k < kRowsPerWarp; ++k) {
    double lane_total = 0.0;
#pragma unroll
    for (int b = 0; b < kPartialsPerLane; ++b) lane_total += loaded[k][b];
    totals[k] = warpSum(lane_total);
  }
  if (lane != 0) return;
#pragma unroll
  for (int k = 0; k < kRowsPerWarp; ++k) {
    const int r = warp + k * kWarps;
    if (r >= kTotalRows) break;
    const int term = r / kPartialRows;
    writeTotal(r % kPartialRows, summed(in, term) ? totals[k] : 0.0, results[term]);
  }
}

__global__ void __launch_bounds__(kThreads)
    gaussNewtonSums(LinearizeInputs in, LinearizeScratch scratch, DeviceTermSums* results) {
  const int term = termOfBlock(in);
  ThreadSums sums;
  if (term == kNonground) {
    addNongroundTerms(in, sums);
  } else {
    addGroundTerms(in, sums);
  }
  writeBlockSums(sums, scratch.partials, term);
  if (lastBlockToFinish(scratch.finished_blocks)) writeTotals(in, scratch.partials, results);
}

}  // namespace

void linearize(const LinearizeInputs& inputs, const LinearizeScratch& scratch, DeviceTermSums* results,
               cudaStream_t stream) {
  const dim3 grid(kReductionBlocks, inputs.nonground && inputs.ground ? kTerms : 1);
  gaussNewtonSums<<<grid, kThreads, 0, stream>>>(inputs, scratch, results);
  checkLaunch("gaussNewtonSums");
}

}  // namespace elo::cuda
