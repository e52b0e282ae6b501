// The point-to-plane term of one correspondence (Eq. 6-9, 15-17). With the left update T <- exp(delta) T
// and p' = T u, the residual e = n^T (p' - v) has the Jacobian J = [n^T, (p' x n)^T] (PAPER_NOTES: the
// moved scan point, not the model vertex). Residuals are weighted by a Geman-McClure kernel (IRLS).
#pragma once

#include "elo/device_types.hpp"

namespace elo {

struct PointToPlane {
  double residual;
  double weight;
  double jacobian[6];
};

// Geman-McClure IRLS weight; a scale of 0 weighs all residuals equally.
ELO_HOST_DEVICE inline double gemanMcClureWeight(double residual, double scale) {
  if (scale <= 0.0) return 1.0;
  const double s2 = scale * scale;
  const double denominator = s2 + residual * residual;
  return s2 * s2 / (denominator * denominator);
}

ELO_HOST_DEVICE inline PointToPlane pointToPlane(const Float3& moved, const Float3& model_vertex, const Float3& normal,
                                                 double kernel_scale) {
  const double residual = dot(normal, moved - model_vertex);
  const Float3 moment = cross(moved, normal);
  return {residual, gemanMcClureWeight(residual, kernel_scale), {normal.x, normal.y, normal.z, moment.x, moment.y, moment.z}};
}

// The weight of a non-ground correspondence for the range of its scan point: range / near_range nearer
// than near_range (registration.near_weight_range; 0: 1 for all). A pixel stands for a patch of surface
// growing with the square of its range; weighed alike, the returns of a structure beside the car outnumber
// the rest of the scene.
ELO_HOST_DEVICE inline double nearWeight(float range, float near_range) {
  return range < near_range ? static_cast<double>(range / near_range) : 1.0;
}

// The term of a non-ground correspondence: pointToPlane() weighed by nearWeight() of `scan_range`, the
// range the scan image holds for the point (the norm of its vertex).
ELO_HOST_DEVICE inline PointToPlane nongroundTerm(const Float3& moved, const Float3& model_vertex,
                                                  const Float3& model_normal, float scan_range, double kernel_scale,
                                                  float near_range) {
  PointToPlane term = pointToPlane(moved, model_vertex, model_normal, kernel_scale);
  term.weight *= nearWeight(scan_range, near_range);
  return term;
}

// The Gauss-Newton sums of a set of correspondences in the packed form both backends accumulate: the
// upper triangle of J^T W J row by row (J^T W J is symmetric, so the lower one is its mirror and costs
// no products), then J^T W e, then the squared error.
constexpr int kJtJValues = 21;
constexpr int kTermValues = kJtJValues + 6 + 1;

namespace detail {

// values[K] += (weight J_I) J_C for every entry (I, C) of the upper triangle from (I, C) on, K counting
// the entries. A recursion over template arguments rather than a loop, so that every compiler unrolls
// it and the sums stay in registers (GCC does not unroll the triangular loop on its own).
template <int I, int C, int K>
ELO_HOST_DEVICE inline void addUpperTriangle(const PointToPlane& term, double* values) {
  if constexpr (C < 6) {
    values[K] += (term.weight * term.jacobian[I]) * term.jacobian[C];
    addUpperTriangle<I, C + 1, K + 1>(term, values);
  } else if constexpr (I + 1 < 6) {
    addUpperTriangle<I + 1, I + 1, K>(term, values);
  }
}

}  // namespace detail

ELO_HOST_DEVICE inline void addToPackedSums(const PointToPlane& term, double* values) {
  detail::addUpperTriangle<0, 0, 0>(term, values);
  const double weighted_residual = term.weight * term.residual;
  for (int i = 0; i < 6; ++i) values[kJtJValues + i] += weighted_residual * term.jacobian[i];
  values[kTermValues - 1] += term.residual * term.residual;
}

}  // namespace elo
