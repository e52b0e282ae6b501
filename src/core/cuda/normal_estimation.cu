// Sec. III-B.3-4 on the GPU: one thread per pixel runs pixelNormal() of normals.hpp, whose agreement with
// the CPU backend's vectorised estimator a CPU test checks. A block takes a tile of kTileRows x kTileCols
// pixels: it first loads their vertices and labels, with the halo their windows reach, into shared memory
// (normal_tile.hpp), and each thread then reads its window from there. Then the non-ground pixels with a
// normal are listed in pixel order, as the CPU backend lists them, for the registration.
#include <stdexcept>
#include <string>

#include "core/cuda/kernels.hpp"
#include "core/cuda/launch.cuh"
#include "core/cuda/normal_tile.hpp"

namespace elo::cuda {

namespace {

// A warp takes 32 adjacent pixels of a row: it loads them, and reads their windows, without bank conflicts.
constexpr int kTileCols = 32;
constexpr int kTileRows = kThreads / kTileCols;

// The shared memory a block uses before a CUDA device must be asked for more (and some cannot give it).
constexpr size_t kSharedBytesPerBlock = 48 * 1024;

__host__ __device__ TileShape blockTile(const NormalParams& params, int block_row, int block_col) {
  return TileShape::around(params, block_row, block_col, kTileRows, kTileCols);
}

// Reads vertices and labels only, and writes its own pixel's normal: no thread reads what another writes,
// but for the tile, which every thread of the block has loaded before any reads it.
__global__ void pixelNormals(DeviceScan scan, NormalParams params, int* registration_flags) {
  extern __shared__ TilePixel tile[];
  const int block_row = static_cast<int>(blockIdx.y) * kTileRows;
  const int block_col = static_cast<int>(blockIdx.x) * kTileCols;
  const TileShape shape = blockTile(params, block_row, block_col);
  for (int slot = static_cast<int>(threadIdx.x); slot < shape.slots(); slot += kThreads) {
    tile[slot] = loadTilePixel(scan, shape, slot);
  }
  __syncthreads();
  const int row = block_row + static_cast<int>(threadIdx.x) / kTileCols;
  const int col = block_col + static_cast<int>(threadIdx.x) % kTileCols;
  if (row >= scan.rows || col >= scan.cols) return;
  const int pixel = row * scan.cols + col;
  const bool usable = scan.usable(pixel);
  const TileImage image{scan.rows, scan.cols, shape, tile, scan.ranges};
  const Float3 normal = usable ? pixelNormal(image, row, col, params) : Float3{0.0f, 0.0f, 0.0f};
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
  const size_t shared_bytes = sizeof(TilePixel) * static_cast<size_t>(blockTile(params, 0, 0).slots());
  if (shared_bytes > kSharedBytesPerBlock) {
    throw std::runtime_error("CUDA backend: normals.max_window_width x normals.max_window_height (" +
                             std::to_string(params.max_window_width) + " x " +
                             std::to_string(params.max_window_height) + ") needs " + std::to_string(shared_bytes) +
                             " bytes of shared memory per block, more than the " +
                             std::to_string(kSharedBytesPerBlock) + " a block can have: use smaller windows");
  }
  const dim3 tiles((scan.cols + kTileCols - 1) / kTileCols, (scan.rows + kTileRows - 1) / kTileRows);
  pixelNormals<<<tiles, kThreads, shared_bytes, stream>>>(scan, params, registration_pixels.flags);
  checkLaunch("pixelNormals");
  const int pixels = scan.pixels();
  exclusiveSum(registration_pixels.flags, registration_pixels.offsets, pixels, registration_pixels.scan_scratch,
               registration_pixels.scan_scratch_bytes, stream);
  listFlagged<<<blocksFor(pixels), kThreads, 0, stream>>>(pixels, registration_pixels);
  checkLaunch("listFlagged");
}

}  // namespace elo::cuda
