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

  // Whether the offers until the next call come from one thread only (runsAlone()). A single writer
  // keeps the smaller key with a plain compare and store: the compare-and-swap's locked instruction,
  // which also waits for every store before it to drain, is then the loop's largest cost.
  void setSingleWriter(bool single) { single_writer_ = single; }

  void offer(size_t pixel, float range, uint32_t source) { offerKey(pixel, closestWinsKey(range, source)); }
  // The smaller key stays.
  void offerKey(size_t pixel, ClosestKey key) {
    ClosestKey current = keys_[pixel].load(std::memory_order_relaxed);
    if (single_writer_) {
      if (key < current) keys_[pixel].store(key, std::memory_order_relaxed);
      return;
    }
    while (key < current && !keys_[pixel].compare_exchange_weak(current, key, std::memory_order_relaxed)) {
    }
  }

  // Asks for the pixel's key ahead of an offer.
  void prefetch(size_t pixel) const { __builtin_prefetch(&keys_[pixel], 1); }

  // The pixel's key so far (kNoClosestKey: no offer).
  ClosestKey key(size_t pixel) const { return keys_[pixel].load(std::memory_order_relaxed); }
  // The pixel's key (kNoClosestKey: no offer), leaving the pixel empty. Only once every offer is in, and
  // by one thread per pixel.
  ClosestKey take(size_t pixel) {
    const ClosestKey key = keys_[pixel].load(std::memory_order_relaxed);
    if (key != kNoClosestKey) keys_[pixel].store(kNoClosestKey, std::memory_order_relaxed);
    return key;
  }

 private:
  std::unique_ptr<std::atomic<ClosestKey>[]> keys_;
  bool single_writer_ = false;
};

}  // namespace elo::cpu
