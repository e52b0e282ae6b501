// PNG plots of an evaluation, drawn by gnuplot (Debian: gnuplot-nox).
#pragma once

#include <Eigen/Geometry>
#include <string>
#include <vector>

#include "elo/eval/kitti_metric.hpp"

namespace elo {

// The plane of the top view: KITTI's camera frame looks down y (x-z), a LiDAR frame down z (x-y);
// `widest_spread` takes the two axes along which the ground truth spreads most.
enum class TopView { widest_spread, camera_xz, lidar_xy };

// Draws the estimated against the ground-truth trajectory from above, then t_rel and r_rel against
// segment length; with empty trajectories, only the two error panels. Returns false, with a warning
// on stderr, when gnuplot is not installed or fails.
bool plotEvaluation(const std::string& png_path, const std::vector<Eigen::Isometry3d>& ground_truth,
                    const std::vector<Eigen::Isometry3d>& estimate,
                    const std::vector<LengthDriftError>& drift_by_length, TopView view = TopView::widest_spread,
                    const std::string& title = "");

}  // namespace elo
