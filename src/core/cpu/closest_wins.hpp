// "The point closer to the sensor wins" for many writers at once (projection and model update). Each
// pixel holds a 64-bit key: the range's float bits above, the source index below. Positive floats order
// like their bit patterns, so an atomic minimum of the key keeps the closest source, and equal ranges
// fall to the lower index: the result does not depend on thread timing. CUDA's atomicMin on 64-bit
// words implements the same scheme.
#pragma once

#include <atomic>
#include <cstdint>
#include <cstring>
#include <memory>

namespace elo::cpu {

class ClosestWins {
 public:
  static constexpr uint64_t kEmpty = ~uint64_t{0};

  void resize(size_t pixels) {
    keys_ = std::make_unique<std::atomic<uint64_t>[]>(pixels);
    size_ = pixels;
    reset();
  }
  void reset() {
    for (size_t i = 0; i < size_; ++i) keys_[i].store(kEmpty, std::memory_order_relaxed);
  }

  void offer(size_t pixel, float range, uint32_t source) {
    uint32_t range_bits;
    std::memcpy(&range_bits, &range, sizeof(range_bits));
    const uint64_t key = (uint64_t{range_bits} << 32) | source;
    uint64_t current = keys_[pixel].load(std::memory_order_relaxed);
    while (key < current && !keys_[pixel].compare_exchange_weak(current, key, std::memory_order_relaxed)) {
    }
  }

  bool occupied(size_t pixel) const { return keys_[pixel].load(std::memory_order_relaxed) != kEmpty; }
  uint32_t winner(size_t pixel) const {
    return static_cast<uint32_t>(keys_[pixel].load(std::memory_order_relaxed) & 0xffffffffu);
  }

 private:
  std::unique_ptr<std::atomic<uint64_t>[]> keys_;
  size_t size_ = 0;
};

}  // namespace elo::cpu
