#include <cuda_runtime.h>

#include "core/cuda/device_probe.hpp"

namespace elo::cuda {

namespace {

// Asking for its attributes shows whether this build holds code the GPU can run.
__global__ void probe() {}

std::string cudaVersion(int version) { return std::to_string(version / 1000) + "." + std::to_string(version % 1000 / 10); }

}  // namespace

std::string unusableReason() {
  int driver = 0;
  cudaDriverGetVersion(&driver);
  if (driver == 0) return "no NVIDIA driver is installed";
  if (driver < CUDART_VERSION) {
    return "the NVIDIA driver supports CUDA " + cudaVersion(driver) + ", older than this build's CUDA " +
           cudaVersion(CUDART_VERSION) + "; update the driver";
  }
  int devices = 0;
  const cudaError_t status = cudaGetDeviceCount(&devices);
  if (status != cudaSuccess) {
    cudaGetLastError();  // clears the error, so that later CUDA calls do not report it again
    return std::string("no usable CUDA device (") + cudaGetErrorString(status) + ")";
  }
  if (devices == 0) return "no CUDA device found";
  cudaFuncAttributes attributes;
  const cudaError_t image = cudaFuncGetAttributes(&attributes, probe);
  if (image == cudaSuccess) return {};
  cudaGetLastError();
  int device = 0;
  cudaDeviceProp properties{};
  cudaGetDevice(&device);
  cudaGetDeviceProperties(&properties, device);
  const std::string capability = std::to_string(properties.major) + "." + std::to_string(properties.minor);
  return std::string("the GPU ") + properties.name + " (compute capability " + capability +
         ") cannot run this build's kernels (" + cudaGetErrorString(image) +
         "); rebuild with -DCMAKE_CUDA_ARCHITECTURES=" + std::to_string(properties.major * 10 + properties.minor);
}

}  // namespace elo::cuda
