// "The point closer to the sensor wins" for many writers at once (projection, BEV map, model update).
// Each pixel or cell holds a 64-bit key: the range's float bits above, the source index below. Positive
// floats order like their bit patterns, so the smallest key holds the closest source, and equal ranges
// fall to the lower index: the winner does not depend on which writer came first. The CPU backend takes
// the minimum with a compare-and-swap loop, the CUDA backend with atomicMin, so both pick the same one.
#pragma once

#include <cstdint>
#include <cstring>

#include "elo/device_types.hpp"

namespace elo {

using ClosestKey = unsigned long long;  // the type CUDA's 64-bit atomicMin takes
static_assert(sizeof(ClosestKey) == 8, "closest-wins keys are 64-bit");

constexpr ClosestKey kNoClosestKey = ~ClosestKey{0};  // no source yet; all bytes 0xff

ELO_HOST_DEVICE inline ClosestKey closestWinsKey(float range, uint32_t source) {
#if defined(__CUDA_ARCH__)
  const uint32_t range_bits = __float_as_uint(range);
#else
  uint32_t range_bits;
  std::memcpy(&range_bits, &range, sizeof(range_bits));
#endif
  return (ClosestKey{range_bits} << 32) | source;
}

ELO_HOST_DEVICE inline uint32_t closestWinsSource(ClosestKey key) { return static_cast<uint32_t>(key & 0xffffffffu); }

ELO_HOST_DEVICE inline float closestWinsRange(ClosestKey key) {
  const uint32_t range_bits = static_cast<uint32_t>(key >> 32);
#if defined(__CUDA_ARCH__)
  return __uint_as_float(range_bits);
#else
  float range;
  std::memcpy(&range, &range_bits, sizeof(range));
  return range;
#endif
}

}  // namespace elo
