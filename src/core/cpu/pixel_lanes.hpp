// SphericalProjection::pixelOf() for 8 points at once, with AVX, for the projection's loop over the
// cloud. Per point, pixelOf() is a chain of divisions and square roots with
// branches on the point's octant that the branch predictor cannot learn; 8 lanes share one chain and the
// branches become selects. Each lane performs pixelOf()'s float operations in its order, so it gives the
// same pixel bit for bit (test_projection_ground_normals.cpp checks it against pixelOf() itself).
// Without AVX, pixelsOfGroup() calls pixelOf() point by point.
#pragma once

#include <cstddef>

#include "elo/device_types.hpp"
#include "elo/sensor/projections.hpp"

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

// Points [0, kPixelLanes) of the array `points` (x, y, z after one another, as Vec3f and Float3 lay
// them out) as lanes of x, y and z: three loads of 128-bit pairs and five shuffles instead of 24
// scalar loads and inserts.
inline void loadPointLanes(const float* points, __m256& x, __m256& y, __m256& z) {
  // [x0 y0 z0 x1 | x4 y4 z4 x5], [y1 z1 x2 y2 | y5 z5 x6 y6], [z2 x3 y3 z3 | z6 x7 y7 z7]
  const __m256 m03 = _mm256_insertf128_ps(_mm256_castps128_ps256(_mm_loadu_ps(points)), _mm_loadu_ps(points + 12), 1);
  const __m256 m14 = _mm256_insertf128_ps(_mm256_castps128_ps256(_mm_loadu_ps(points + 4)), _mm_loadu_ps(points + 16), 1);
  const __m256 m25 = _mm256_insertf128_ps(_mm256_castps128_ps256(_mm_loadu_ps(points + 8)), _mm_loadu_ps(points + 20), 1);
  const __m256 xy = _mm256_shuffle_ps(m14, m25, _MM_SHUFFLE(2, 1, 3, 2));  // [x2 y2 x3 y3 | x6 y6 x7 y7]
  const __m256 yz = _mm256_shuffle_ps(m03, m14, _MM_SHUFFLE(1, 0, 2, 1));  // [y0 z0 y1 z1 | y4 z4 y5 z5]
  x = _mm256_shuffle_ps(m03, xy, _MM_SHUFFLE(2, 0, 3, 0));
  y = _mm256_shuffle_ps(yz, xy, _MM_SHUFFLE(3, 1, 2, 0));
  z = _mm256_shuffle_ps(yz, m25, _MM_SHUFFLE(3, 0, 3, 1));
}

// Bit k set where lane k of x, y and z is finite (x - x is 0 for a finite x, NaN otherwise).
inline unsigned finiteLanes(__m256 x, __m256 y, __m256 z) {
  const __m256 zero = _mm256_setzero_ps();
  const __m256 finite = _mm256_and_ps(
      _mm256_cmp_ps(_mm256_sub_ps(x, x), zero, _CMP_EQ_OQ),
      _mm256_and_ps(_mm256_cmp_ps(_mm256_sub_ps(y, y), zero, _CMP_EQ_OQ), _mm256_cmp_ps(_mm256_sub_ps(z, z), zero, _CMP_EQ_OQ)));
  return static_cast<unsigned>(_mm256_movemask_ps(finite));
}

// found(first + k, row, col, range) for each lane k of `usable` whose point (x[k], y[k], z[k])
// pixelOf() accepts (pixelsOfLanes()), in order.
template <typename Found>
void foundPixelsOfLanes(const SphericalProjection& projection, size_t first, unsigned usable, __m256 x, __m256 y,
                        __m256 z, const Found& found) {
  float range[kPixelLanes];
  int row[kPixelLanes], col[kPixelLanes];
  for (unsigned accepted = usable & pixelsOfLanes(projection, x, y, z, row, col, range); accepted != 0;
       accepted &= accepted - 1) {
    const int lane = __builtin_ctz(accepted);
    found(first + lane, row[lane], col[lane], range[lane]);
  }
}

#endif  // ELO_PIXEL_LANES

// The pixels of items [first, first + kPixelLanes) below `count`: `point(i, p)` gives item i's point p
// (false: it has none); each point pixelOf() accepts goes to `found(i, row, col, range)`, range its norm().
template <typename Point, typename Found>
void pixelsOfGroup(const SphericalProjection& projection, size_t first, size_t count, const Point& point,
                   const Found& found) {
#ifdef ELO_PIXEL_LANES
  float x[kPixelLanes], y[kPixelLanes], z[kPixelLanes];
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
  foundPixelsOfLanes(projection, first, usable, _mm256_setr_ps(x[0], x[1], x[2], x[3], x[4], x[5], x[6], x[7]),
                     _mm256_setr_ps(y[0], y[1], y[2], y[3], y[4], y[5], y[6], y[7]),
                     _mm256_setr_ps(z[0], z[1], z[2], z[3], z[4], z[5], z[6], z[7]), found);
#else
  for (size_t i = first; i < first + kPixelLanes && i < count; ++i) {
    Float3 p;
    int row = 0;
    int col = 0;
    if (point(i, p) && projection.pixelOf(p, row, col)) found(i, row, col, norm(p));
  }
#endif
}

// pixelsOfGroup() for the finite points among `count` whose coordinates `xyz` holds (x, y, z after one
// another, as a vector of Vec3f lays them out), taken as they are: a whole group's lanes come from
// loadPointLanes().
template <typename Found>
void pixelsOfPoints(const SphericalProjection& projection, const float* xyz, size_t first, size_t count,
                    const Found& found) {
#ifdef ELO_PIXEL_LANES
  if (first + kPixelLanes <= count) {
    __m256 x, y, z;
    loadPointLanes(xyz + 3 * first, x, y, z);
    foundPixelsOfLanes(projection, first, finiteLanes(x, y, z), x, y, z, found);
    return;
  }
#endif
  pixelsOfGroup(
      projection, first, count,
      [&](size_t i, Float3& p) {
        p = {xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]};
        return isFinite(p);
      },
      found);
}

}  // namespace elo::cpu
