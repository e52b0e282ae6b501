#include "elo/sim/rng.hpp"

#include <cmath>

namespace elo::sim {
namespace {

uint64_t splitMix64(uint64_t x) {
  x += 0x9e3779b97f4a7c15ULL;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
  return x ^ (x >> 31);
}

}  // namespace

uint64_t mixSeed(uint64_t seed, uint64_t a, uint64_t b, uint64_t c) {
  uint64_t mixed = splitMix64(seed);
  mixed = splitMix64(mixed ^ a);
  mixed = splitMix64(mixed ^ b);
  return splitMix64(mixed ^ c);
}

Rng::Rng(uint64_t seed) : engine_(seed) {}

double Rng::uniform() {
  // The top 53 bits fill a double's mantissa exactly.
  return static_cast<double>(engine_() >> 11) * 0x1.0p-53;
}

double Rng::uniform(double low, double high) { return low + (high - low) * uniform(); }

int Rng::uniformInt(int low, int high) {
  const double span = static_cast<double>(high) - static_cast<double>(low) + 1.0;
  const int offset = static_cast<int>(std::floor(uniform() * span));
  return low + offset;
}

bool Rng::chance(double probability) { return uniform() < probability; }

double Rng::gaussian() {
  if (has_spare_gaussian_) {
    has_spare_gaussian_ = false;
    return spare_gaussian_;
  }
  const double u1 = 1.0 - uniform();  // (0, 1]: log(0) never happens
  const double u2 = uniform();
  const double radius = std::sqrt(-2.0 * std::log(u1));
  const double angle = 2.0 * M_PI * u2;
  spare_gaussian_ = radius * std::sin(angle);
  has_spare_gaussian_ = true;
  return radius * std::cos(angle);
}

double Rng::gaussian(double mean, double stddev) { return mean + stddev * gaussian(); }

}  // namespace elo::sim
