// Trajectory errors beside the KITTI metric: relative pose error between consecutive frames, and
// absolute trajectory error after a rigid alignment.
#pragma once

#include <Eigen/Geometry>
#include <cstddef>
#include <vector>

namespace elo {

struct RelativePoseError {
  size_t pairs = 0;
  double translation_rmse_m = 0.0;
  double rotation_rmse_deg = 0.0;
};

struct AbsoluteTrajectoryError {
  size_t frames = 0;
  double translation_rmse_m = 0.0;
  Eigen::Isometry3d alignment = Eigen::Isometry3d::Identity();  // maps estimate positions onto ground truth
};

// RMSE of inv(gt_i^-1 gt_i+1) * (est_i^-1 est_i+1) over consecutive frames. Throws
// std::invalid_argument naming both counts when the trajectories have different lengths.
RelativePoseError relativePoseError(const std::vector<Eigen::Isometry3d>& ground_truth,
                                    const std::vector<Eigen::Isometry3d>& estimate);

// RMSE of position differences after aligning the estimate's positions to the ground truth's with the
// rigid (rotation and translation, no scale) least-squares fit of Umeyama. Throws like
// relativePoseError.
AbsoluteTrajectoryError absoluteTrajectoryError(const std::vector<Eigen::Isometry3d>& ground_truth,
                                                const std::vector<Eigen::Isometry3d>& estimate);

}  // namespace elo
