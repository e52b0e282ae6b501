#include <stdexcept>

#include "core/cpu/cpu_backend.hpp"

namespace elo {

std::unique_ptr<Backend> makeBackend(const Config& config) {
  switch (config.runtime.backend) {
    case BackendKind::cpu:
      return std::make_unique<cpu::CpuBackend>(config);
    case BackendKind::cuda:
      break;
  }
  throw std::runtime_error("runtime.backend 'cuda' is not available: this build has no CUDA backend");
}

}  // namespace elo
