// Least-squares planes of a few points (Eq. 10-11), for the normals of the range image and of the BEV
// ground model, on both backends.
#pragma once

#include <cfloat>
#include <cmath>

#include "elo/device_types.hpp"

namespace elo {

struct SymmetricMatrix3 {
  float xx, xy, xz, yy, yz, zz;
};

// The first and second moments of a set of points, accumulated one point at a time. Points are given
// relative to a nearby origin (the centre of a normal window), so float sums keep their precision.
struct PointMoments {
  Float3 sum{0.0f, 0.0f, 0.0f};
  SymmetricMatrix3 outer{0.0f, 0.0f, 0.0f, 0.0f, 0.0f, 0.0f};  // sum of p p^T
  int count = 0;

  ELO_HOST_DEVICE void add(const Float3& p) {
    sum = sum + p;
    outer.xx += p.x * p.x;
    outer.xy += p.x * p.y;
    outer.xz += p.x * p.z;
    outer.yy += p.y * p.y;
    outer.yz += p.y * p.z;
    outer.zz += p.z * p.z;
    ++count;
  }

  // The covariance of the points about their mean.
  ELO_HOST_DEVICE SymmetricMatrix3 covariance() const {
    const float n = static_cast<float>(count);
    const Float3 mean = sum / n;
    return {outer.xx / n - mean.x * mean.x, outer.xy / n - mean.x * mean.y, outer.xz / n - mean.x * mean.z,
            outer.yy / n - mean.y * mean.y, outer.yz / n - mean.y * mean.z, outer.zz / n - mean.z * mean.z};
  }
};

struct SymmetricEigen {
  float eigenvalues[3];   // ascending
  Float3 smallest;        // unit eigenvector of eigenvalues[0]
};

namespace detail {

// atan, sin and cos from + - * / alone (Cephes' single-precision polynomials, within 2e-7), where libm's
// and the GPU's differ in the last bit: the eigenvalues must come out the same on both backends.
ELO_HOST_DEVICE inline float arctangent(float x) {  // x >= 0
  float base = 0.0f;
  if (x > 2.414213562373095f) {
    base = 1.5707963267948966f;
    x = -1.0f / x;
  } else if (x > 0.4142135623730950f) {
    base = 0.7853981633974483f;
    x = (x - 1.0f) / (x + 1.0f);
  }
  const float z = x * x;
  return base + (((8.05374449538e-2f * z - 1.38776856032e-1f) * z + 1.99777106478e-1f) * z - 3.33329491539e-1f) * z * x + x;
}

// atan2(y, x) for y >= 0, in [0, pi].
ELO_HOST_DEVICE inline float upperArctangent2(float y, float x) {
  if (x == 0.0f) return y > 0.0f ? 1.5707963267948966f : 0.0f;
  const float angle = arctangent(y / std::fabs(x));
  return x > 0.0f ? angle : 3.1415926535897932f - angle;
}

ELO_HOST_DEVICE inline float sineNearZero(float x) {  // |x| <= pi/4
  const float z = x * x;
  return ((-1.9515295891e-4f * z + 8.3321608736e-3f) * z - 1.6666654611e-1f) * z * x + x;
}
ELO_HOST_DEVICE inline float cosineNearZero(float x) {  // |x| <= pi/4
  const float z = x * x;
  return ((2.443315711809948e-5f * z - 1.388731625493765e-3f) * z + 4.166664568298827e-2f) * z * z - 0.5f * z + 1.0f;
}

// The roots of the characteristic polynomial of `m` in closed form, ascending. `m` is shifted to a zero
// trace and scaled into [-1, 1], as Eigen's computeDirect does, to keep the cubic well conditioned.
ELO_HOST_DEVICE inline void characteristicRoots(const SymmetricMatrix3& m, float roots[3]) {
  const float inv3 = 1.0f / 3.0f;
  const float sqrt3 = std::sqrt(3.0f);
  // x^3 - c2 x^2 + c1 x - c0 = 0
  const float c0 = m.xx * m.yy * m.zz + 2.0f * m.xy * m.xz * m.yz - m.xx * m.yz * m.yz - m.yy * m.xz * m.xz -
                   m.zz * m.xy * m.xy;
  const float c1 = m.xx * m.yy - m.xy * m.xy + m.xx * m.zz - m.xz * m.xz + m.yy * m.zz - m.yz * m.yz;
  const float c2 = m.xx + m.yy + m.zz;
  const float c2_over_3 = c2 * inv3;
  float a_over_3 = (c2 * c2_over_3 - c1) * inv3;
  a_over_3 = a_over_3 > 0.0f ? a_over_3 : 0.0f;
  const float half_b = 0.5f * (c0 + c2_over_3 * (2.0f * c2_over_3 * c2_over_3 - c1));
  float q = a_over_3 * a_over_3 * a_over_3 - half_b * half_b;
  q = q > 0.0f ? q : 0.0f;  // also turns -0 into +0, which atan2 tells apart
  const float rho = std::sqrt(a_over_3);
  const float theta = upperArctangent2(std::sqrt(q), half_b) * inv3;  // in [0, pi/3]
  const bool small = theta <= 0.7853981633974483f;
  const float reduced = small ? theta : 1.5707963267948966f - theta;  // within pi/4 of zero
  const float cos_theta = small ? cosineNearZero(reduced) : sineNearZero(reduced);
  const float sin_theta = small ? sineNearZero(reduced) : cosineNearZero(reduced);
  roots[0] = c2_over_3 - rho * (cos_theta + sqrt3 * sin_theta);
  roots[1] = c2_over_3 - rho * (cos_theta - sqrt3 * sin_theta);
  roots[2] = c2_over_3 + 2.0f * rho * cos_theta;
}

ELO_HOST_DEVICE inline SymmetricMatrix3 minusDiagonal(const SymmetricMatrix3& m, float value) {
  return {m.xx - value, m.xy, m.xz, m.yy - value, m.yz, m.zz - value};
}

// The unit kernel of the rank-2 matrix `m`: the longer cross product of its column with the largest
// diagonal entry and one of the other two. `representative` gets that column, which is orthogonal to
// the kernel.
ELO_HOST_DEVICE inline Float3 kernelOfRankTwo(const SymmetricMatrix3& m, Float3& representative) {
  const Float3 columns[3] = {{m.xx, m.xy, m.xz}, {m.xy, m.yy, m.yz}, {m.xz, m.yz, m.zz}};
  const float diagonal[3] = {std::fabs(m.xx), std::fabs(m.yy), std::fabs(m.zz)};
  int i0 = 0;
  if (diagonal[1] > diagonal[i0]) i0 = 1;
  if (diagonal[2] > diagonal[i0]) i0 = 2;
  representative = columns[i0];
  const Float3 c0 = cross(representative, columns[(i0 + 1) % 3]);
  const Float3 c1 = cross(representative, columns[(i0 + 2) % 3]);
  const float n0 = squaredNorm(c0);
  const float n1 = squaredNorm(c1);
  return n0 > n1 ? c0 / std::sqrt(n0) : c1 / std::sqrt(n1);
}

}  // namespace detail

// Eigenvalues and the smallest eigenvector of a symmetric 3x3 matrix: Eigen's direct solver
// (SelfAdjointEigenSolver::computeDirect) ported for both backends, with its trigonometry from basic
// operations, forming only the eigenvector a plane fit needs. Where the two smallest eigenvalues coincide (collinear points), any unit vector orthogonal
// to the largest eigenvector is returned.
ELO_HOST_DEVICE inline SymmetricEigen symmetricEigen(const SymmetricMatrix3& matrix) {
  const float shift = (matrix.xx + matrix.yy + matrix.zz) / 3.0f;
  SymmetricMatrix3 m = detail::minusDiagonal(matrix, shift);
  float scale = 0.0f;
  const float entries[6] = {m.xx, m.xy, m.xz, m.yy, m.yz, m.zz};
  for (const float entry : entries) scale = std::fabs(entry) > scale ? std::fabs(entry) : scale;
  if (scale > 0.0f) m = {m.xx / scale, m.xy / scale, m.xz / scale, m.yy / scale, m.yz / scale, m.zz / scale};

  float roots[3];
  detail::characteristicRoots(m, roots);
  SymmetricEigen result;
  result.smallest = {1.0f, 0.0f, 0.0f};  // all three eigenvalues equal: every direction is an eigenvector
  if (roots[2] - roots[0] > FLT_EPSILON) {
    const float upper_gap = roots[2] - roots[1];
    const float lower_gap = roots[1] - roots[0];
    Float3 representative;
    if (upper_gap <= lower_gap) {
      result.smallest = detail::kernelOfRankTwo(detail::minusDiagonal(m, roots[0]), representative);
    } else {
      const Float3 largest = detail::kernelOfRankTwo(detail::minusDiagonal(m, roots[2]), representative);
      if (lower_gap <= 2.0f * FLT_EPSILON * upper_gap) {
        const Float3 orthogonal = representative - largest * dot(largest, representative);
        result.smallest = orthogonal / norm(orthogonal);
      } else {
        result.smallest = detail::kernelOfRankTwo(detail::minusDiagonal(m, roots[0]), representative);
      }
    }
  }
  for (int i = 0; i < 3; ++i) result.eigenvalues[i] = roots[i] * scale + shift;
  return result;
}

struct PlaneFit {
  Float3 normal{0.0f, 0.0f, 0.0f};  // eigenvector of the smallest eigenvalue
  float curvature = 1.0f;           // lambda3 / (lambda1 + lambda2 + lambda3)
  bool valid = false;
};

// The plane of points whose covariance has the eigen-decomposition `eigen` (Eq. 10-11).
ELO_HOST_DEVICE inline PlaneFit planeOf(const SymmetricEigen& eigen) {
  PlaneFit fit;
  const float sum = eigen.eigenvalues[0] + eigen.eigenvalues[1] + eigen.eigenvalues[2];
  if (!(sum > 0.0f)) return fit;
  fit.normal = eigen.smallest / norm(eigen.smallest);
  fit.curvature = (eigen.eigenvalues[0] > 0.0f ? eigen.eigenvalues[0] : 0.0f) / sum;
  fit.valid = isFinite(fit.normal);
  return fit;
}

// The plane of the points whose moments are given: eigen-decomposition of their covariance.
ELO_HOST_DEVICE inline PlaneFit fitPlane(const PointMoments& moments) {
  if (moments.count < 3) return {};
  return planeOf(symmetricEigen(moments.covariance()));
}

// Below this smallest eigenvalue of their horizontal spread (5 cm across the line) ground points lie on
// one scan ring, whose points tell the road's slope along the ring but not across it. The range noise
// alone spreads a ring's points 2-3 cm across, along the beams, which slope down to the road: a plane
// fitted to them leans towards the sensor, and the odometry took that lean for a pitch while the car was
// slow and its ground model still one set of rings (VLP-16: 0.7 deg in the first 20 scans from rest,
// then its height drifting 1 % of the distance; docs/accuracy.md). Two rings lie 10 cm or more apart.
constexpr float kMinCrossSpread = 2.5e-3f;
// Below this largest eigenvalue (1 cm along) the points are one spot: no plane.
constexpr float kMinAlongSpread = 1e-4f;

// The upward normal of the ground patch `points`: the plane z = a x + b y + c fitted by least squares (a
// ground patch is never vertical, so this 2x2 solve replaces an eigen-decomposition); for the points of
// one ring, the plane through the ring's slope along it, level across it; zero for (nearly) one spot.
ELO_HOST_DEVICE inline Float3 groundPlaneNormal(const Float3* points, int count, const Float3& origin) {
  const Float3 none{0.0f, 0.0f, 0.0f};
  if (count < 3) return none;
  PointMoments moments;
  for (int i = 0; i < count; ++i) moments.add(points[i] - origin);
  const SymmetricMatrix3 c = moments.covariance();
  const float determinant = c.xx * c.yy - c.xy * c.xy;
  const float half_trace = 0.5f * (c.xx + c.yy);
  const float discriminant = half_trace * half_trace - determinant;
  const float root = std::sqrt(discriminant > 0.0f ? discriminant : 0.0f);
  const float largest_spread = half_trace + root;
  if (!(largest_spread >= kMinAlongSpread)) return none;
  Float3 normal{0.0f, 0.0f, 1.0f};
  if (half_trace - root >= kMinCrossSpread) {
    normal.x = -(c.yy * c.xz - c.xy * c.yz) / determinant;
    normal.y = -(c.xx * c.yz - c.xy * c.xz) / determinant;
  } else {
    // The ring's direction u, the eigenvector of the largest spread: of its two forms, the longer (the
    // other may be all rounding), or an axis when the spread is the same every way.
    float ux = largest_spread - c.yy;
    float uy = c.xy;
    if (c.xy * c.xy + (largest_spread - c.xx) * (largest_spread - c.xx) > ux * ux + uy * uy) {
      ux = c.xy;
      uy = largest_spread - c.xx;
    }
    const float length = std::sqrt(ux * ux + uy * uy);
    ux = length > 0.0f ? ux / length : 1.0f;
    uy = length > 0.0f ? uy / length : 0.0f;
    const float slope = (ux * c.xz + uy * c.yz) / largest_spread;
    normal.x = -slope * ux;
    normal.y = -slope * uy;
  }
  return normal / norm(normal);
}

}  // namespace elo
