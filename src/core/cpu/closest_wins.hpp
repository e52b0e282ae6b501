// "The point closer to the sensor wins" for many writers at once (projection and model update), with
// the key of closest_wins_key.hpp that the CUDA backend's atomicMin uses too. The minimum is taken with
// a compare-and-swap loop, so the result does not depend on thread timing.
#pragma once

#include <atomic>
#include <cstdint>
#include <memory>

#include "core/common/closest_wins_key.hpp"

namespace elo::cpu {

class ClosestWins {
 public:
  void resize(size_t pixels) {
    keys_ = std::make_unique<std::atomic<ClosestKey>[]>(pixels);
    size_ = pixels;
    reset();
  }
  void reset() {
    for (size_t i = 0; i < size_; ++i) keys_[i].store(kNoClosestKey, std::memory_order_relaxed);
  }

  void offer(size_t pixel, float range, uint32_t source) { offerKey(pixel, closestWinsKey(range, source)); }
  // The smaller key stays.
  void offerKey(size_t pixel, ClosestKey key) {
    ClosestKey current = keys_[pixel].load(std::memory_order_relaxed);
    while (key < current && !keys_[pixel].compare_exchange_weak(current, key, std::memory_order_relaxed)) {
    }
  }

  bool occupied(size_t pixel) const { return keys_[pixel].load(std::memory_order_relaxed) != kNoClosestKey; }
  float range(size_t pixel) const { return closestWinsRange(keys_[pixel].load(std::memory_order_relaxed)); }
  uint32_t winner(size_t pixel) const { return closestWinsSource(keys_[pixel].load(std::memory_order_relaxed)); }

 private:
  std::unique_ptr<std::atomic<ClosestKey>[]> keys_;
  size_t size_ = 0;
};

}  // namespace elo::cpu
