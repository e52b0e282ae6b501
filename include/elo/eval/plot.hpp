// PNG plots of an evaluation, drawn by gnuplot (Debian: gnuplot-nox).
#pragma once

#include <Eigen/Geometry>
#include <string>
#include <utility>
#include <vector>

#include "elo/eval/kitti_metric.hpp"

namespace elo {

// The plane of the top view: KITTI's camera frame looks down y (x-z), a LiDAR frame down z (x-y);
// `widest_spread` takes the two axes along which the ground truth spreads most.
enum class TopView { widest_spread, camera_xz, lidar_xy };

// What the top view shows: the two pose coordinates plotted across and up, their ranges (one scale for
// both), and the panel's height in pixels on a canvas 1280 pixels wide. The ranges hold both
// trajectories with a margin; the narrower is widened to at least 0.3 of the wider, so that a long
// straight drive is not drawn as a thin strip with crammed labels; and the top has room for the key.
// The panel is as tall as the width gives at that scale, within 360 to 900 pixels.
struct TopViewFrame {
  std::pair<int, int> axes{0, 1};
  Eigen::Vector2d low = Eigen::Vector2d::Zero();
  Eigen::Vector2d high = Eigen::Vector2d::Zero();
  int height_px = 0;
};
TopViewFrame topViewFrame(const std::vector<Eigen::Isometry3d>& ground_truth,
                          const std::vector<Eigen::Isometry3d>& estimate, TopView view);

// Draws the estimated against the ground-truth trajectory from above (topViewFrame), and below it t_rel
// and r_rel against segment length; with empty trajectories, only the two error panels. Returns false, with a warning
// on stderr, when gnuplot is not installed or fails.
bool plotEvaluation(const std::string& png_path, const std::vector<Eigen::Isometry3d>& ground_truth,
                    const std::vector<Eigen::Isometry3d>& estimate,
                    const std::vector<LengthDriftError>& drift_by_length, TopView view = TopView::widest_spread,
                    const std::string& title = "");

}  // namespace elo
