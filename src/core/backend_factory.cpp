#include <stdexcept>

#include "core/cpu/cpu_backend.hpp"
#if defined(ELO_WITH_CUDA)
#include "core/cuda/cuda_backend.hpp"
#include "core/cuda/device_probe.hpp"
#endif

namespace elo {

std::string cudaUnavailableReason() {
#if defined(ELO_WITH_CUDA)
  return cuda::unusableReason();
#else
  return "this build has no CUDA backend (no CUDA compiler was found, or it was configured with -DELO_CUDA=OFF)";
#endif
}

std::unique_ptr<Backend> makeBackend(const Config& config, std::string* warning) {
  if (config.runtime.backend == BackendKind::cpu) return std::make_unique<cpu::CpuBackend>(config);
  const std::string reason = cudaUnavailableReason();
#if defined(ELO_WITH_CUDA)
  if (reason.empty()) return std::make_unique<cuda::CudaBackend>(config);
#endif
  if (!config.runtime.backend_fallback) {
    throw std::runtime_error("runtime.backend is 'cuda', but " + reason +
                             " (set runtime.backend_fallback to run on the CPU instead)");
  }
  if (warning != nullptr) {
    *warning = "runtime.backend is 'cuda', but " + reason + ": running on the CPU backend (runtime.backend_fallback)";
  }
  return std::make_unique<cpu::CpuBackend>(config);
}

}  // namespace elo
