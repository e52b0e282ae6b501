// The host's TermSums of the packed sums both backends accumulate (point_to_plane.hpp).
#pragma once

#include "core/common/point_to_plane.hpp"
#include "elo/pipeline/backend.hpp"

namespace elo {

inline TermSums unpackTermSums(const double* values, int candidates, int inliers) {
  TermSums sums;
  int k = 0;
  for (int i = 0; i < 6; ++i) {
    for (int j = i; j < 6; ++j) sums.JtJ(i, j) = sums.JtJ(j, i) = values[k++];
  }
  for (int i = 0; i < 6; ++i) sums.Jte(i) = values[kJtJValues + i];
  sums.squared_error = values[kTermValues - 1];
  sums.candidates = candidates;
  sums.inliers = inliers;
  return sums;
}

}  // namespace elo
