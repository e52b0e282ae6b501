// Pose algebra the metrics of elo_eval share (not installed).
#pragma once

#include <Eigen/Geometry>
#include <stdexcept>
#include <string>
#include <vector>

namespace elo::eval_detail {

// A general (not transposed) inverse, as the devkit's Matrix::inv: ground-truth rotations are
// orthonormal only to the ~1e-7 of their text, and a transpose would report that as error.
inline Eigen::Isometry3d generalInverse(const Eigen::Isometry3d& pose) { return pose.inverse(Eigen::Affine); }

// The motion from `from` to `to`, in the frame of `from`.
inline Eigen::Isometry3d relativeMotion(const Eigen::Isometry3d& from, const Eigen::Isometry3d& to) {
  return generalInverse(from) * to;
}

inline void requireSameLength(const std::vector<Eigen::Isometry3d>& ground_truth,
                              const std::vector<Eigen::Isometry3d>& estimate) {
  if (ground_truth.size() != estimate.size()) {
    throw std::invalid_argument("the ground truth has " + std::to_string(ground_truth.size()) +
                                " poses but the estimate has " + std::to_string(estimate.size()));
  }
}

}  // namespace elo::eval_detail
