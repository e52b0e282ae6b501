// SphericalProjection::pixelOf() for 8 points at once, with AVX: the projection's and the model update's
// loops over points and pixels. Per point, pixelOf() is a chain of divisions and square roots with
// branches on the point's octant that the branch predictor cannot learn; 8 lanes share one chain and the
// branches become selects. Each lane performs pixelOf()'s float operations in its order, so it gives the
// same pixel bit for bit (test_projection_ground_normals.cpp checks it against pixelOf() itself).
// Without AVX, pixelsOfGroup() calls pixelOf() point by point.
#pragma once

#include <cstddef>

#include "elo/device_types.hpp"
#include "elo/projections.hpp"

#if defined(__AVX__)
#define ELO_PIXEL_LANES 1
#include <immintrin.h>

#include <cmath>
#endif

namespace elo::cpu {

constexpr int kPixelLanes = 8;

#ifdef ELO_PIXEL_LANES

namespace lanes {

inline __m256 select(__m256 condition, __m256 if_true, __m256 if_false) {
  return _mm256_blendv_ps(if_false, if_true, condition);
}

// fastAtan2() lane by lane.
inline __m256 fastAtan2(__m256 y, __m256 x) {
  const __m256 sign = _mm256_set1_ps(-0.0f);
  const __m256 zero = _mm256_setzero_ps();
  const __m256 ax = _mm256_andnot_ps(sign, x);
  const __m256 ay = _mm256_andnot_ps(sign, y);
  const __m256 x_larger = _mm256_cmp_ps(ax, ay, _CMP_GT_OQ);
  const __m256 largest = select(x_larger, ax, ay);
  const __m256 a = _mm256_div_ps(select(x_larger, ay, ax), largest);
  const __m256 s = _mm256_mul_ps(a, a);
  __m256 poly = _mm256_mul_ps(s, _mm256_set1_ps(0.0208351f));
  poly = _mm256_mul_ps(s, _mm256_add_ps(_mm256_set1_ps(-0.0851330f), poly));
  poly = _mm256_mul_ps(s, _mm256_add_ps(_mm256_set1_ps(0.1801410f), poly));
  poly = _mm256_mul_ps(s, _mm256_add_ps(_mm256_set1_ps(-0.3302995f), poly));
  __m256 r = _mm256_mul_ps(a, _mm256_add_ps(_mm256_set1_ps(0.9998660f), poly));
  r = select(_mm256_cmp_ps(ay, ax, _CMP_GT_OQ), _mm256_sub_ps(_mm256_set1_ps(1.57079632679f), r), r);
  r = select(_mm256_cmp_ps(x, zero, _CMP_LT_OQ), _mm256_sub_ps(_mm256_set1_ps(3.14159265359f), r), r);
  r = select(_mm256_cmp_ps(y, zero, _CMP_LT_OQ), _mm256_xor_ps(r, sign), r);
  return select(_mm256_cmp_ps(largest, zero, _CMP_EQ_OQ), zero, r);
}

}  // namespace lanes

// pixelOf() of the points (px[k], py[k], pz[k]), k < kPixelLanes: bit k of the result is set when it
// accepts point k, whose row and col it then gave; range[k] is the point's norm() (the square root of
// pixelOf()'s squared range, summed in norm()'s order), for every lane.
inline unsigned pixelsOfLanes(const SphericalProjection& projection, __m256 px, __m256 py, __m256 pz, int* row,
                              int* col, float* range) {
  const __m256 horizontal_squared = _mm256_add_ps(_mm256_mul_ps(px, px), _mm256_mul_ps(py, py));
  const __m256 range_squared = _mm256_add_ps(horizontal_squared, _mm256_mul_ps(pz, pz));
  _mm256_storeu_ps(range, _mm256_sqrt_ps(range_squared));
  const __m256 in_range =
      _mm256_and_ps(_mm256_cmp_ps(range_squared, _mm256_set1_ps(projection.min_range * projection.min_range), _CMP_GE_OQ),
                    _mm256_cmp_ps(range_squared, _mm256_set1_ps(projection.max_range * projection.max_range), _CMP_LE_OQ));
  const __m256 azimuth = lanes::fastAtan2(py, px);
  const __m256 elevation = lanes::fastAtan2(pz, _mm256_sqrt_ps(horizontal_squared));
  const __m256 cols = _mm256_set1_ps(static_cast<float>(projection.cols));
  const __m256 rows = _mm256_set1_ps(static_cast<float>(projection.rows));
  const __m256 u = _mm256_mul_ps(
      _mm256_mul_ps(_mm256_set1_ps(0.5f),
                    _mm256_sub_ps(_mm256_set1_ps(1.0f), _mm256_mul_ps(azimuth, _mm256_set1_ps(static_cast<float>(M_1_PI))))),
      cols);
  const __m256 v = _mm256_mul_ps(
      _mm256_div_ps(_mm256_sub_ps(_mm256_set1_ps(projection.fov_up), elevation), _mm256_set1_ps(projection.fov_span)),
      rows);
  // Whole numbers far below 2^24 from here on, so float arithmetic on them is the int arithmetic of pixelOf().
  const __m256 zero = _mm256_setzero_ps();
  const __m256 v_floor = _mm256_floor_ps(v);
  __m256 u_floor = _mm256_floor_ps(u);
  u_floor = lanes::select(_mm256_cmp_ps(u_floor, cols, _CMP_GE_OQ), _mm256_sub_ps(u_floor, cols), u_floor);
  u_floor = lanes::select(_mm256_cmp_ps(u_floor, zero, _CMP_LT_OQ), _mm256_add_ps(u_floor, cols), u_floor);
  const __m256 accepted = _mm256_and_ps(in_range, _mm256_and_ps(_mm256_cmp_ps(v_floor, zero, _CMP_GE_OQ),
                                                                _mm256_cmp_ps(v_floor, rows, _CMP_LT_OQ)));
  _mm256_storeu_si256(reinterpret_cast<__m256i*>(row), _mm256_cvttps_epi32(v_floor));
  _mm256_storeu_si256(reinterpret_cast<__m256i*>(col), _mm256_cvttps_epi32(u_floor));
  return static_cast<unsigned>(_mm256_movemask_ps(accepted));
}

#endif  // ELO_PIXEL_LANES

// The pixels of items [first, first + kPixelLanes) below `count`: `point(i, p)` gives item i's point p
// (false: it has none); each point pixelOf() accepts goes to `found(i, row, col, range)`, range its norm().
template <typename Point, typename Found>
void pixelsOfGroup(const SphericalProjection& projection, size_t first, size_t count, const Point& point,
                   const Found& found) {
#ifdef ELO_PIXEL_LANES
  float x[kPixelLanes], y[kPixelLanes], z[kPixelLanes], range[kPixelLanes];
  int row[kPixelLanes], col[kPixelLanes];
  unsigned usable = 0;
  for (int lane = 0; lane < kPixelLanes; ++lane) {
    const size_t i = first + lane;
    Float3 p{0.0f, 0.0f, 0.0f};
    const bool has_point = i < count && point(i, p);
    usable |= has_point ? 1u << lane : 0u;
    x[lane] = has_point ? p.x : 0.0f;
    y[lane] = has_point ? p.y : 0.0f;
    z[lane] = has_point ? p.z : 0.0f;
  }
  // Lanes set from registers: a vector load of the 8 floats just stored one by one would wait for them.
  const unsigned accepted =
      usable & pixelsOfLanes(projection, _mm256_setr_ps(x[0], x[1], x[2], x[3], x[4], x[5], x[6], x[7]),
                             _mm256_setr_ps(y[0], y[1], y[2], y[3], y[4], y[5], y[6], y[7]),
                             _mm256_setr_ps(z[0], z[1], z[2], z[3], z[4], z[5], z[6], z[7]), row, col, range);
  for (int lane = 0; lane < kPixelLanes; ++lane) {
    if (accepted & (1u << lane)) found(first + lane, row[lane], col[lane], range[lane]);
  }
#else
  for (size_t i = first; i < first + kPixelLanes && i < count; ++i) {
    Float3 p;
    int row = 0;
    int col = 0;
    if (point(i, p) && projection.pixelOf(p, row, col)) found(i, row, col, norm(p));
  }
#endif
}

}  // namespace elo::cpu
