// Whether this machine can run the CUDA backend.
#pragma once

#include <string>

namespace elo::cuda {

// Why the CUDA backend cannot run here (no driver, no device, no kernel image for the GPU), or empty
// when it can.
std::string unusableReason();

}  // namespace elo::cuda
