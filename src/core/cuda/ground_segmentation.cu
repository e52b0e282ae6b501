// Sec. III-C.1 on the GPU, one thread per pixel. A block takes a strip of kStripColumns columns, all rows:
// each warp reads one column's occupancy as ballots into shared memory (ColumnBits of ground.hpp), then
// each thread labels its pixels from the bits and the vertices of the neighbours they name
// (pixelGroundLabel()), which are the neighbours the CPU's walk down the column (segmentColumn()) uses:
// the labels are the same. Unoccupied pixels keep their label, as on the CPU.
#include "core/cuda/kernels.hpp"
#include "core/cuda/launch.cuh"

namespace elo::cuda {

namespace {

// A warp labels 8 adjacent pixels (one 32-byte sector of ranges) in each of 4 rows.
constexpr int kStripColumns = 8;
constexpr int kStripRows = kThreads / kStripColumns;
constexpr int kWarp = 32;
static_assert(kThreads == kStripColumns * kWarp, "one warp per column of the strip reads its occupancy");

__host__ __device__ int occupancyWords(int rows) { return (rows + 31) / 32; }

// Shared memory: occupancy[word * kStripColumns + strip column], occupancyWords(rows) words per column.
__global__ void labelPixels(DeviceScan scan, GroundBand band) {
  extern __shared__ uint32_t occupancy[];
  const int words = occupancyWords(scan.rows);
  const int first_col = static_cast<int>(blockIdx.x) * kStripColumns;
  {
    const int strip_col = static_cast<int>(threadIdx.x) / kWarp;
    const int lane = static_cast<int>(threadIdx.x) % kWarp;
    const int col = first_col + strip_col;
    for (int w = 0; w < words; ++w) {
      const int row = w * kWarp + lane;
      const bool occupied = col < scan.cols && row < scan.rows && scan.occupied(row * scan.cols + col);
      const uint32_t bits = __ballot_sync(0xffffffffu, occupied);
      if (lane == 0) occupancy[w * kStripColumns + strip_col] = bits;
    }
  }
  __syncthreads();
  const int strip_col = static_cast<int>(threadIdx.x) % kStripColumns;
  const int col = first_col + strip_col;
  if (col >= scan.cols) return;
  const ColumnBits column{occupancy + strip_col, kStripColumns, words};
  for (int row = static_cast<int>(threadIdx.x) / kStripColumns; row < scan.rows; row += kStripRows) {
    if (column.occupied(row)) scan.setLabel(row * scan.cols + col, pixelGroundLabel(scan, column, row, col, band));
  }
}

__global__ void labelOccupiedNonground(DeviceScan scan) {
  const int pixel = globalThread();
  if (pixel < scan.pixels() && scan.occupied(pixel)) scan.labels[pixel] = PixelLabel::nonground;
}

}  // namespace

void segmentGround(const DeviceScan& scan, const GroundBand& band, cudaStream_t stream) {
  const int strips = (scan.cols + kStripColumns - 1) / kStripColumns;
  const size_t shared_bytes = sizeof(uint32_t) * kStripColumns * occupancyWords(scan.rows);
  labelPixels<<<strips, kThreads, shared_bytes, stream>>>(scan, band);
  checkLaunch("labelPixels");
}

void labelAllNonground(const DeviceScan& scan, cudaStream_t stream) {
  labelOccupiedNonground<<<blocksFor(scan.pixels()), kThreads, 0, stream>>>(scan);
  checkLaunch("labelOccupiedNonground");
}

}  // namespace elo::cuda
