// The CPU's accumulator of the packed Gauss-Newton sums of point_to_plane.hpp. Each packed value gets
// the same product added in the same order as addToPackedSums() gives it, so the sums are the same bit
// for bit (the library is built with -ffp-contract=off: a multiply and an add, never fused). The 28
// values are held as seven 4-wide vectors: a local accumulator stays in registers over a block's loop,
// where the scalar sums were loaded and stored once per correspondence and value.
#pragma once

#include "core/common/point_to_plane.hpp"

namespace elo::cpu {

class LaneSums {
 public:
  void add(const PointToPlane& term) {
    const double* j = term.jacobian;
    const double w = term.weight;
    const double w0 = w * j[0], w1 = w * j[1], w2 = w * j[2], w3 = w * j[3], w4 = w * j[4], w5 = w * j[5];
    const double wr = w * term.residual;
    const double r = term.residual;
    // The upper triangle row by row: (w J_i) J_c; then (w e) J_i; then e e (point_to_plane.hpp).
    lanes_[0] += Lanes{w0, w0, w0, w0} * Lanes{j[0], j[1], j[2], j[3]};
    lanes_[1] += Lanes{w0, w0, w1, w1} * Lanes{j[4], j[5], j[1], j[2]};
    lanes_[2] += Lanes{w1, w1, w1, w2} * Lanes{j[3], j[4], j[5], j[2]};
    lanes_[3] += Lanes{w2, w2, w2, w3} * Lanes{j[3], j[4], j[5], j[3]};
    lanes_[4] += Lanes{w3, w3, w4, w4} * Lanes{j[4], j[5], j[4], j[5]};
    lanes_[5] += Lanes{w5, wr, wr, wr} * Lanes{j[5], j[0], j[1], j[2]};
    lanes_[6] += Lanes{wr, wr, wr, r} * Lanes{j[3], j[4], j[5], r};
  }

  LaneSums& operator+=(const LaneSums& other) {
    for (int lane = 0; lane < kLanes; ++lane) lanes_[lane] += other.lanes_[lane];
    return *this;
  }

  // The packed values, in addToPackedSums()'s order (kTermValues of them).
  void copyTo(double* values) const {
    for (int v = 0; v < kTermValues; ++v) values[v] = lanes_[v / 4][v % 4];
  }

 private:
  typedef double Lanes __attribute__((vector_size(32)));
  static constexpr int kLanes = 7;
  static_assert(kLanes * 4 == kTermValues, "the packed values fill the lanes");

  Lanes lanes_[kLanes] = {};
};

}  // namespace elo::cpu
