// Every metric of one trajectory against its ground truth, and the pooled figures over sequences:
// what elo_eval prints a row of.
#pragma once

#include <Eigen/Geometry>
#include <string>
#include <vector>

#include "elo/eval/error_breakdown.hpp"
#include "elo/eval/kitti_metric.hpp"
#include "elo/eval/trajectory_error.hpp"

namespace elo {

struct TrajectoryEvaluation {
  std::string name;
  size_t frames = 0;
  double length_m = 0.0;  // ground-truth path length
  std::vector<SegmentError> segments;
  size_t segments_left_out = 0;  // those holding an excluded frame
  DriftError drift;
  std::vector<SegmentComponents> components;  // of each segment
  ErrorBreakdown breakdown;
  RelativePoseError rpe;
  AbsoluteTrajectoryError ate;
};

// The KITTI metric over segments of `segment_lengths` (m) starting every `start_step` frames, those
// holding a frame of `excluded_frames` left out (RPE and ATE keep every frame). Throws
// std::invalid_argument naming both counts when the trajectories have different lengths.
TrajectoryEvaluation evaluateTrajectory(const std::string& name, const std::vector<Eigen::Isometry3d>& ground_truth,
                                        const std::vector<Eigen::Isometry3d>& estimate,
                                        const std::vector<double>& segment_lengths = kittiSegmentLengths(),
                                        size_t start_step = kKittiStartFrameStep,
                                        const std::vector<FrameRange>& excluded_frames = {});

// The figures over all sequences: KITTI drift and its breakdown over the segments of all of them (as the
// devkit pools), RPE over all frame pairs and ATE over all frames (each sequence aligned on its own, so
// the pooled `ate.alignment` is the identity).
TrajectoryEvaluation poolEvaluations(const std::string& name, const std::vector<TrajectoryEvaluation>& sequences);

}  // namespace elo
