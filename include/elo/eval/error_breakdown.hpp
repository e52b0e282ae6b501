// What the KITTI metric's segment errors are made of: a t_rel says how far off a drive ends, its
// breakdown says whether the heading, the tilt, the scale or the height is wrong. Each segment's
// relative error E = (gt_first^-1 gt_last)^-1 (est_first^-1 est_last) lies in the frame of the segment's
// last ground-truth pose (x forward, y left, z up: the LiDAR frame); its rotation is split into yaw,
// pitch and roll about those axes, and its translation into the direction of travel (the ground truth's
// chord from the segment's first pose to its last), the horizontal across it, and the rest (height).
// Not a devkit figure.
#pragma once

#include <Eigen/Geometry>
#include <vector>

#include "elo/eval/kitti_metric.hpp"

namespace elo {

// One segment's error components per metre of its nominal length.
struct SegmentComponents {
  double yaw = 0.0;     // rad per m: the rotation error's components (rotation vector) about z, y and x
  double pitch = 0.0;
  double roll = 0.0;
  double along = 0.0;   // m per m along the direction of travel: + when the estimate travels too far
  double cross = 0.0;   // m per m across it, + to the left
  double height = 0.0;  // m per m perpendicular to both, + up
};

// The mean components over segments, in the units of the KITTI metric. Angles, cross-track and height
// are mean absolute values (a drift to the left in one bend and to the right in the next both count);
// along-track is a signed mean: a scale error, + when the estimate travels too far. NaN without segments.
struct ErrorBreakdown {
  size_t segments = 0;
  double heading_deg_per_100m = 0.0;
  double pitch_deg_per_100m = 0.0;
  double roll_deg_per_100m = 0.0;
  double along_track_percent = 0.0;
  double cross_track_percent = 0.0;
  double height_percent = 0.0;
};

// The components of each of `segments` (from kittiSegmentErrors over the same trajectories).
std::vector<SegmentComponents> segmentComponents(const std::vector<Eigen::Isometry3d>& ground_truth,
                                                 const std::vector<Eigen::Isometry3d>& estimate,
                                                 const std::vector<SegmentError>& segments);

// The mean over `components`; sequences pool by concatenating their components, as the devkit pools
// segments.
ErrorBreakdown averageBreakdown(const std::vector<SegmentComponents>& components);

}  // namespace elo
