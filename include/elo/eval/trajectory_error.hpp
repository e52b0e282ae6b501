// Trajectory errors beside the KITTI metric: relative pose error between consecutive frames, absolute
// trajectory error after a rigid alignment, the error of one pose relative to the first, and, without
// ground truth, the gap between a drive run
// forward and in reverse.
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

// The error of the estimate's pose `frame` in the frame of its first pose, against the ground truth's in
// the frame of its own first: inv(gt_0^-1 gt_frame) * (est_0^-1 est_frame). What a run started at any
// scan (elo_run --start), a car already moving, gets wrong in its first scans (docs/real_drives.md).
struct PoseError {
  double translation_m = 0.0;
  double rotation_deg = 0.0;
};

// Throws std::invalid_argument when either trajectory has no pose `frame`.
PoseError poseErrorFromFirst(const std::vector<Eigen::Isometry3d>& ground_truth,
                             const std::vector<Eigen::Isometry3d>& estimate, size_t frame);

// How far a drive run forward and the same scans run in reverse fail to close: `forward[i]` is scan i
// in scan 0's frame, `reverse[j]` scan n-1-j in scan n-1's frame, so forward.back() * reverse.back() is
// the identity for a perfect odometry. It needs no ground truth. A gap g means that at least one run
// ends g/2 or more off; a small gap proves less, since errors that flip with the direction of travel (a
// scale error) cancel.
struct ForwardBackwardGap {
  size_t frames = 0;
  double length_m = 0.0;  // the forward run's path length
  double translation_m = 0.0;
  double rotation_deg = 0.0;
};

// Throws std::invalid_argument naming both counts when the runs have different lengths, and for empty
// runs.
ForwardBackwardGap forwardBackwardGap(const std::vector<Eigen::Isometry3d>& forward,
                                      const std::vector<Eigen::Isometry3d>& reverse);

}  // namespace elo
