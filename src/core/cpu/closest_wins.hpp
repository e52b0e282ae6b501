// "The point closer to the sensor wins" for many writers at once (projection and model update), with
// the key of closest_wins_key.hpp that the CUDA backend's atomicMin uses too. The minimum is taken with
// a compare-and-swap loop, so the result does not depend on thread timing. Every pixel starts empty; the
// stage that reads the winners takes each pixel's key with take(), which empties it again, so no pass
// of its own (a serial one, or one more sweep over the array) clears it for the next scan.
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
    for (size_t i = 0; i < pixels; ++i) keys_[i].store(kNoClosestKey, std::memory_order_relaxed);
  }

  void offer(size_t pixel, float range, uint32_t source) { offerKey(pixel, closestWinsKey(range, source)); }
  // The smaller key stays.
  void offerKey(size_t pixel, ClosestKey key) {
    ClosestKey current = keys_[pixel].load(std::memory_order_relaxed);
    while (key < current && !keys_[pixel].compare_exchange_weak(current, key, std::memory_order_relaxed)) {
    }
  }

  float range(size_t pixel) const { return closestWinsRange(keys_[pixel].load(std::memory_order_relaxed)); }
  // The pixel's key (kNoClosestKey: no offer), leaving the pixel empty. Only once every offer is in, and
  // by one thread per pixel.
  ClosestKey take(size_t pixel) {
    const ClosestKey key = keys_[pixel].load(std::memory_order_relaxed);
    if (key != kNoClosestKey) keys_[pixel].store(kNoClosestKey, std::memory_order_relaxed);
    return key;
  }

 private:
  std::unique_ptr<std::atomic<ClosestKey>[]> keys_;
};

}  // namespace elo::cpu
