// Random numbers that are identical on every machine and standard library. std::mt19937_64's raw
// output is fully specified by the C++ standard, but the std:: distributions are not (libstdc++ and
// libc++ turn the same engine output into different numbers), so uniforms and Gaussians are derived
// here from the raw 64-bit words.
#pragma once

#include <cstdint>
#include <random>

namespace elo::sim {

// Mixes a base seed with up to three indices (a frame, a beam, a lot...) into a new seed, so that the
// streams of neighbouring indices are unrelated (SplitMix64's finaliser after each step).
uint64_t mixSeed(uint64_t seed, uint64_t a, uint64_t b = 0, uint64_t c = 0);

class Rng {
 public:
  explicit Rng(uint64_t seed);

  double uniform();                           // [0, 1), 53 random bits
  double uniform(double low, double high);    // [low, high)
  int uniformInt(int low, int high);          // [low, high], both included
  bool chance(double probability);
  double gaussian();                          // standard normal (Box-Muller)
  double gaussian(double mean, double stddev);

 private:
  std::mt19937_64 engine_;
  double spare_gaussian_ = 0.0;  // Box-Muller makes two numbers a draw
  bool has_spare_gaussian_ = false;
};

}  // namespace elo::sim
