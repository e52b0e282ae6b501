// Exclusive prefix sums of 0/1 flags (CUB), which give each flagged item its slot in a compact array, in
// item order. Integer sums: the same result whatever the order CUB adds in.
#include <cub/device/device_scan.cuh>

#include "core/cuda/device_buffer.hpp"
#include "core/cuda/kernels.hpp"

namespace elo::cuda {

size_t exclusiveSumScratchBytes(int max_items) {
  size_t bytes = 0;
  check(cub::DeviceScan::ExclusiveSum(nullptr, bytes, static_cast<const int*>(nullptr), static_cast<int*>(nullptr),
                                      max_items),
        "cub::DeviceScan::ExclusiveSum (scratch size)");
  return bytes;
}

void exclusiveSum(const int* flags, int* offsets, int items, void* scratch, size_t scratch_bytes, cudaStream_t stream) {
  check(cub::DeviceScan::ExclusiveSum(scratch, scratch_bytes, flags, offsets, items, stream),
        "cub::DeviceScan::ExclusiveSum");
}

}  // namespace elo::cuda
