// symmetricEigen() of plane_fit.hpp for 8 matrices at once, with AVX, for the plane fits of the normal
// estimation. Per matrix, the solve is a chain of divisions, square roots and polynomials with branches
// on the roots' spacing and on which column is largest, which no predictor learns; 8 lanes share one
// chain and the branches become selects (both sides computed, one kept). Each lane performs the scalar
// function's float operations in its order, so it gives the same eigenvalues and eigenvector bit for bit
// (test_shared_math.cpp checks it against symmetricEigen() itself). Without AVX, symmetricEigens() calls
// symmetricEigen() matrix by matrix.
#pragma once

#include <cfloat>

#include "core/common/plane_fit.hpp"

#if defined(__AVX__)
#define ELO_EIGEN_LANES 1
#include <immintrin.h>
#endif

namespace elo::cpu {

constexpr int kEigenLanes = 8;

#ifdef ELO_EIGEN_LANES

namespace eigen_lanes {

using Lanes = __m256;

struct Lanes3 {
  Lanes x, y, z;
};

struct SymmetricLanes {
  Lanes xx, xy, xz, yy, yz, zz;
};

inline Lanes all(float value) { return _mm256_set1_ps(value); }
inline Lanes plus(Lanes a, Lanes b) { return _mm256_add_ps(a, b); }
inline Lanes minus(Lanes a, Lanes b) { return _mm256_sub_ps(a, b); }
inline Lanes times(Lanes a, Lanes b) { return _mm256_mul_ps(a, b); }
inline Lanes over(Lanes a, Lanes b) { return _mm256_div_ps(a, b); }
// The comparisons are false where an operand is NaN, as C++'s are.
inline Lanes greater(Lanes a, Lanes b) { return _mm256_cmp_ps(a, b, _CMP_GT_OQ); }
inline Lanes lessOrEqual(Lanes a, Lanes b) { return _mm256_cmp_ps(a, b, _CMP_LE_OQ); }
inline Lanes equal(Lanes a, Lanes b) { return _mm256_cmp_ps(a, b, _CMP_EQ_OQ); }
inline Lanes select(Lanes condition, Lanes if_true, Lanes if_false) {
  return _mm256_blendv_ps(if_false, if_true, condition);
}
inline Lanes3 select(Lanes condition, const Lanes3& a, const Lanes3& b) {
  return {select(condition, a.x, b.x), select(condition, a.y, b.y), select(condition, a.z, b.z)};
}
inline Lanes magnitude(Lanes a) { return _mm256_andnot_ps(all(-0.0f), a); }  // std::fabs
// `condition ? value : 0` written as plane_fit.hpp writes its clamps, `value > 0 ? value : 0`.
inline Lanes positivePart(Lanes value) { return select(greater(value, all(0.0f)), value, all(0.0f)); }

inline Lanes dot(const Lanes3& a, const Lanes3& b) {
  return plus(plus(times(a.x, b.x), times(a.y, b.y)), times(a.z, b.z));
}
inline Lanes3 cross(const Lanes3& a, const Lanes3& b) {
  return {minus(times(a.y, b.z), times(a.z, b.y)), minus(times(a.z, b.x), times(a.x, b.z)),
          minus(times(a.x, b.y), times(a.y, b.x))};
}
inline Lanes3 scaled(const Lanes3& a, Lanes s) { return {times(a.x, s), times(a.y, s), times(a.z, s)}; }
inline Lanes3 divided(const Lanes3& a, Lanes s) { return {over(a.x, s), over(a.y, s), over(a.z, s)}; }
inline Lanes3 difference(const Lanes3& a, const Lanes3& b) { return {minus(a.x, b.x), minus(a.y, b.y), minus(a.z, b.z)}; }

inline SymmetricLanes minusDiagonal(const SymmetricLanes& m, Lanes value) {
  return {minus(m.xx, value), m.xy, m.xz, minus(m.yy, value), m.yz, minus(m.zz, value)};
}

// detail::arctangent(), x >= 0: the three ranges' arguments computed in every lane, one kept.
inline Lanes arctangent(Lanes x) {
  const Lanes large = greater(x, all(2.414213562373095f));
  const Lanes middle = greater(x, all(0.4142135623730950f));
  const Lanes base = select(large, all(1.5707963267948966f), select(middle, all(0.7853981633974483f), all(0.0f)));
  x = select(large, over(all(-1.0f), x), select(middle, over(minus(x, all(1.0f)), plus(x, all(1.0f))), x));
  const Lanes z = times(x, x);
  Lanes poly = minus(times(all(8.05374449538e-2f), z), all(1.38776856032e-1f));
  poly = plus(times(poly, z), all(1.99777106478e-1f));
  poly = minus(times(poly, z), all(3.33329491539e-1f));
  return plus(plus(base, times(times(poly, z), x)), x);
}

// detail::upperArctangent2(), y >= 0.
inline Lanes upperArctangent2(Lanes y, Lanes x) {
  const Lanes angle = arctangent(over(y, magnitude(x)));
  const Lanes general = select(greater(x, all(0.0f)), angle, minus(all(3.1415926535897932f), angle));
  const Lanes on_axis = select(greater(y, all(0.0f)), all(1.5707963267948966f), all(0.0f));
  return select(equal(x, all(0.0f)), on_axis, general);
}

inline Lanes sineNearZero(Lanes x) {
  const Lanes z = times(x, x);
  Lanes poly = plus(times(all(-1.9515295891e-4f), z), all(8.3321608736e-3f));
  poly = minus(times(poly, z), all(1.6666654611e-1f));
  return plus(times(times(poly, z), x), x);
}

inline Lanes cosineNearZero(Lanes x) {
  const Lanes z = times(x, x);
  Lanes poly = minus(times(all(2.443315711809948e-5f), z), all(1.388731625493765e-3f));
  poly = plus(times(poly, z), all(4.166664568298827e-2f));
  return plus(minus(times(times(poly, z), z), times(all(0.5f), z)), all(1.0f));
}

// detail::characteristicRoots().
inline void characteristicRoots(const SymmetricLanes& m, Lanes roots[3]) {
  const Lanes inv3 = all(1.0f / 3.0f);
  const Lanes sqrt3 = all(std::sqrt(3.0f));
  Lanes c0 = plus(times(times(m.xx, m.yy), m.zz), times(times(times(all(2.0f), m.xy), m.xz), m.yz));
  c0 = minus(c0, times(times(m.xx, m.yz), m.yz));
  c0 = minus(c0, times(times(m.yy, m.xz), m.xz));
  c0 = minus(c0, times(times(m.zz, m.xy), m.xy));
  Lanes c1 = minus(times(m.xx, m.yy), times(m.xy, m.xy));
  c1 = plus(c1, times(m.xx, m.zz));
  c1 = minus(c1, times(m.xz, m.xz));
  c1 = plus(c1, times(m.yy, m.zz));
  c1 = minus(c1, times(m.yz, m.yz));
  const Lanes c2 = plus(plus(m.xx, m.yy), m.zz);
  const Lanes c2_over_3 = times(c2, inv3);
  const Lanes a_over_3 = positivePart(times(minus(times(c2, c2_over_3), c1), inv3));
  const Lanes half_b =
      times(all(0.5f), plus(c0, times(c2_over_3, minus(times(times(all(2.0f), c2_over_3), c2_over_3), c1))));
  const Lanes q = positivePart(minus(times(times(a_over_3, a_over_3), a_over_3), times(half_b, half_b)));
  const Lanes rho = _mm256_sqrt_ps(a_over_3);
  const Lanes theta = times(upperArctangent2(_mm256_sqrt_ps(q), half_b), inv3);
  const Lanes small = lessOrEqual(theta, all(0.7853981633974483f));
  const Lanes reduced = select(small, theta, minus(all(1.5707963267948966f), theta));
  const Lanes cosine = cosineNearZero(reduced);
  const Lanes sine = sineNearZero(reduced);
  const Lanes cos_theta = select(small, cosine, sine);
  const Lanes sin_theta = select(small, sine, cosine);
  roots[0] = minus(c2_over_3, times(rho, plus(cos_theta, times(sqrt3, sin_theta))));
  roots[1] = minus(c2_over_3, times(rho, minus(cos_theta, times(sqrt3, sin_theta))));
  roots[2] = plus(c2_over_3, times(times(all(2.0f), rho), cos_theta));
}

// detail::kernelOfRankTwo(): the column with the largest diagonal entry and the other two chosen by
// selects, then the same two cross products.
inline Lanes3 kernelOfRankTwo(const SymmetricLanes& m, Lanes3& representative) {
  const Lanes3 column0{m.xx, m.xy, m.xz};
  const Lanes3 column1{m.xy, m.yy, m.yz};
  const Lanes3 column2{m.xz, m.yz, m.zz};
  const Lanes d0 = magnitude(m.xx);
  const Lanes d1 = magnitude(m.yy);
  const Lanes d2 = magnitude(m.zz);
  const Lanes first = greater(d1, d0);
  const Lanes second = greater(d2, select(first, d1, d0));
  representative = select(second, column2, select(first, column1, column0));
  const Lanes3 next = select(second, column0, select(first, column2, column1));
  const Lanes3 after = select(second, column1, select(first, column0, column2));
  const Lanes3 c0 = cross(representative, next);
  const Lanes3 c1 = cross(representative, after);
  const Lanes n0 = dot(c0, c0);
  const Lanes n1 = dot(c1, c1);
  return select(greater(n0, n1), divided(c0, _mm256_sqrt_ps(n0)), divided(c1, _mm256_sqrt_ps(n1)));
}

// symmetricEigen() of the matrices in the lanes.
inline void symmetricEigen(const SymmetricLanes& matrix, Lanes eigenvalues[3], Lanes3& smallest) {
  const Lanes shift = over(plus(plus(matrix.xx, matrix.yy), matrix.zz), all(3.0f));
  SymmetricLanes m = minusDiagonal(matrix, shift);
  Lanes scale = all(0.0f);
  for (const Lanes entry : {m.xx, m.xy, m.xz, m.yy, m.yz, m.zz}) {
    scale = select(greater(magnitude(entry), scale), magnitude(entry), scale);
  }
  const Lanes scaling = greater(scale, all(0.0f));
  m = {select(scaling, over(m.xx, scale), m.xx), select(scaling, over(m.xy, scale), m.xy),
       select(scaling, over(m.xz, scale), m.xz), select(scaling, over(m.yy, scale), m.yy),
       select(scaling, over(m.yz, scale), m.yz), select(scaling, over(m.zz, scale), m.zz)};

  Lanes roots[3];
  characteristicRoots(m, roots);
  const Lanes upper_gap = minus(roots[2], roots[1]);
  const Lanes lower_gap = minus(roots[1], roots[0]);
  Lanes3 unused;
  const Lanes3 of_smallest = kernelOfRankTwo(minusDiagonal(m, roots[0]), unused);
  Lanes3 representative;
  const Lanes3 largest = kernelOfRankTwo(minusDiagonal(m, roots[2]), representative);
  const Lanes3 orthogonal = difference(representative, scaled(largest, dot(largest, representative)));
  const Lanes3 orthogonal_unit = divided(orthogonal, _mm256_sqrt_ps(dot(orthogonal, orthogonal)));
  const Lanes nearly_equal = lessOrEqual(lower_gap, times(all(2.0f * FLT_EPSILON), upper_gap));
  const Lanes3 distinct = select(lessOrEqual(upper_gap, lower_gap), of_smallest,
                                 select(nearly_equal, orthogonal_unit, of_smallest));
  const Lanes3 every_direction{all(1.0f), all(0.0f), all(0.0f)};  // all three eigenvalues equal
  smallest = select(greater(minus(roots[2], roots[0]), all(FLT_EPSILON)), distinct, every_direction);
  for (int i = 0; i < 3; ++i) eigenvalues[i] = plus(times(roots[i], scale), shift);
}

}  // namespace eigen_lanes

// symmetricEigen() of matrices[0..count), count <= kEigenLanes, into eigens.
inline void symmetricEigens(const SymmetricMatrix3* matrices, int count, SymmetricEigen* eigens) {
  alignas(32) float entries[6][kEigenLanes];
  for (int lane = 0; lane < kEigenLanes; ++lane) {
    const SymmetricMatrix3& m = matrices[lane < count ? lane : 0];  // unused lanes repeat the first
    entries[0][lane] = m.xx;
    entries[1][lane] = m.xy;
    entries[2][lane] = m.xz;
    entries[3][lane] = m.yy;
    entries[4][lane] = m.yz;
    entries[5][lane] = m.zz;
  }
  const eigen_lanes::SymmetricLanes m{_mm256_load_ps(entries[0]), _mm256_load_ps(entries[1]),
                                      _mm256_load_ps(entries[2]), _mm256_load_ps(entries[3]),
                                      _mm256_load_ps(entries[4]), _mm256_load_ps(entries[5])};
  eigen_lanes::Lanes values[3];
  eigen_lanes::Lanes3 smallest;
  eigen_lanes::symmetricEigen(m, values, smallest);
  alignas(32) float out[6][kEigenLanes];
  for (int i = 0; i < 3; ++i) _mm256_store_ps(out[i], values[i]);
  _mm256_store_ps(out[3], smallest.x);
  _mm256_store_ps(out[4], smallest.y);
  _mm256_store_ps(out[5], smallest.z);
  for (int lane = 0; lane < count; ++lane) {
    eigens[lane].eigenvalues[0] = out[0][lane];
    eigens[lane].eigenvalues[1] = out[1][lane];
    eigens[lane].eigenvalues[2] = out[2][lane];
    eigens[lane].smallest = {out[3][lane], out[4][lane], out[5][lane]};
  }
}

#else

inline void symmetricEigens(const SymmetricMatrix3* matrices, int count, SymmetricEigen* eigens) {
  for (int i = 0; i < count; ++i) eigens[i] = symmetricEigen(matrices[i]);
}

#endif

}  // namespace elo::cpu
