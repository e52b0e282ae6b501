// The Eigen-free types of the code both backends run: per-element math written once, compiled for the
// host by the C++ compiler and for the GPU by nvcc (ELO_HOST_DEVICE). Float3 and Rigid3f stand in for
// Eigen, which device code cannot use cleanly.
//
// Both backends must round every float operation of this code the same way, or a point near a pixel
// border lands in different pixels. C++ lets a compiler contract a*b+c into one fused multiply-add, and
// GCC and nvcc contract in different places, so elo_core is compiled with -ffp-contract=off and its CUDA
// code with --fmad=false: each product and sum is then rounded exactly as written, on both sides. Square
// roots and divisions are correctly rounded on both.
#pragma once

#include <cmath>
#include <cstdint>

#if defined(__CUDACC__)
#define ELO_HOST_DEVICE __host__ __device__
#else
#define ELO_HOST_DEVICE
#endif

namespace elo {

enum class PixelLabel : uint8_t { empty = 0, nonground = 1, ground = 2 };

// Laid out like Eigen::Vector3f (three packed floats), so arrays of either copy byte for byte.
struct Float3 {
  float x;
  float y;
  float z;
};

ELO_HOST_DEVICE inline Float3 operator+(const Float3& a, const Float3& b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
ELO_HOST_DEVICE inline Float3 operator-(const Float3& a, const Float3& b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
ELO_HOST_DEVICE inline Float3 operator-(const Float3& a) { return {-a.x, -a.y, -a.z}; }
ELO_HOST_DEVICE inline Float3 operator*(const Float3& a, float s) { return {a.x * s, a.y * s, a.z * s}; }
ELO_HOST_DEVICE inline Float3 operator/(const Float3& a, float s) { return {a.x / s, a.y / s, a.z / s}; }

ELO_HOST_DEVICE inline float dot(const Float3& a, const Float3& b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
ELO_HOST_DEVICE inline Float3 cross(const Float3& a, const Float3& b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
ELO_HOST_DEVICE inline float squaredNorm(const Float3& a) { return dot(a, a); }
ELO_HOST_DEVICE inline float norm(const Float3& a) { return std::sqrt(squaredNorm(a)); }
ELO_HOST_DEVICE inline float squaredDistance(const Float3& a, const Float3& b) { return squaredNorm(a - b); }
// Normals are unit vectors or exactly zero ("no normal").
ELO_HOST_DEVICE inline bool isZero(const Float3& a) { return a.x == 0.0f && a.y == 0.0f && a.z == 0.0f; }
// `condition ? a : b`, component by component: a select the CPU's loops vectorise (a choice between
// whole structs is a choice between their addresses, which does not).
ELO_HOST_DEVICE inline Float3 choose(bool condition, const Float3& a, const Float3& b) {
  return {condition ? a.x : b.x, condition ? a.y : b.y, condition ? a.z : b.z};
}
ELO_HOST_DEVICE inline bool isFinite(const Float3& a) {
  return std::isfinite(a.x) && std::isfinite(a.y) && std::isfinite(a.z);
}

// a * b + c with one rounding, where the hardware has it: on the GPU, and on hosts built with FMA (the
// default -march=native on any recent CPU: one instruction, which GCC also vectorises). A host without
// FMA rounds twice, and can differ from the GPU in the last bit there.
ELO_HOST_DEVICE inline float fusedMultiplyAdd(float a, float b, float c) {
#if defined(__CUDA_ARCH__)
  return fmaf(a, b, c);
#elif defined(__FMA__) || defined(__ARM_FEATURE_FMA)
  return __builtin_fmaf(a, b, c);
#else
  return a * b + c;
#endif
}

// A rigid transform in float, rotation row-major: what the kernels apply to every point.
struct Rigid3f {
  float r[9];
  Float3 t;

  ELO_HOST_DEVICE Float3 rotate(const Float3& p) const {
    return {r[0] * p.x + r[1] * p.y + r[2] * p.z, r[3] * p.x + r[4] * p.y + r[5] * p.z,
            r[6] * p.x + r[7] * p.y + r[8] * p.z};
  }
  ELO_HOST_DEVICE Float3 apply(const Float3& p) const { return rotate(p) + t; }
};

}  // namespace elo
