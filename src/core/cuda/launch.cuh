// Launch shapes and the launch check shared by the kernels of the CUDA backend.
#pragma once

#include "core/cuda/device_buffer.hpp"

namespace elo::cuda {

constexpr int kThreads = 256;  // per block, every kernel

// Blocks of kThreads covering `items` (one thread each).
inline int blocksFor(int items) { return (items + kThreads - 1) / kThreads; }

// Kernels whose item count lives on the device loop over it with a fixed grid of this many blocks, so
// the host need not read the count first.
constexpr int kGridStrideBlocks = 256;
// Grid-stride kernels whose items wait on memory (atomics) want more threads in flight: this many blocks of
// kThreads fill an H100 (132 SMs of 2048 threads) once.
constexpr int kWideGridBlocks = 1024;

// A bad launch (configuration, no kernel image) shows at once; a fault in a kernel shows at the next
// synchronisation, which checks too.
inline void checkLaunch(const char* kernel) { check(cudaGetLastError(), kernel); }

__device__ inline int globalThread() { return static_cast<int>(blockIdx.x * blockDim.x + threadIdx.x); }
__device__ inline int gridThreads() { return static_cast<int>(gridDim.x * blockDim.x); }

}  // namespace elo::cuda
