// The KITTI odometry benchmark metric, as the devkit's evaluate_odometry.cpp defines it: relative
// errors of all segments of 100, 200, ..., 800 m of ground-truth path, starting at every 10th frame.
// The devkit computes in float; this computes the same quantities in double. Other segment lengths
// (e.g. 10..100 m for drives shorter than 800 m) keep the devkit's rules.
#pragma once

#include <Eigen/Geometry>
#include <cstddef>
#include <string>
#include <vector>

namespace elo {

// The devkit's `lengths` (m) and `step_size` (frames between segment starts).
const std::vector<double>& kittiSegmentLengths();
constexpr size_t kKittiStartFrameStep = 10;

struct SegmentError {
  size_t first_frame = 0;
  size_t last_frame = 0;
  double length = 0.0;             // m: the nominal segment length
  double rotation_error = 0.0;     // rad per m
  double translation_error = 0.0;  // m per m
  // The translation error's x-y part (m per m), in the LiDAR frame of the segment's last scan, where the
  // devkit's error lies: the drift in the plane, told apart from a drift in height. Not a devkit figure.
  double horizontal_error = 0.0;
};

// Mean segment errors in the units the benchmark reports; NaN when there are no segments (a
// trajectory shorter than 100 m).
struct DriftError {
  size_t segments = 0;
  double t_rel_percent = 0.0;
  double r_rel_deg_per_100m = 0.0;
  double t_rel_horizontal_percent = 0.0;  // the mean horizontal_error, in %
};

struct LengthDriftError {
  double length = 0.0;  // m
  DriftError error;
};

// Path length (m) travelled from frame 0 to each frame: the sum of distances between consecutive poses.
std::vector<double> trajectoryDistances(const std::vector<Eigen::Isometry3d>& poses);

// Every segment of `ground_truth` of each of `lengths` (m), starting every `start_step` frames, with its
// error in `estimate`. Throws std::invalid_argument naming both counts when the trajectories have
// different lengths.
std::vector<SegmentError> kittiSegmentErrors(const std::vector<Eigen::Isometry3d>& ground_truth,
                                             const std::vector<Eigen::Isometry3d>& estimate,
                                             const std::vector<double>& lengths = kittiSegmentLengths(),
                                             size_t start_step = kKittiStartFrameStep);

// A run of frames, both ends included.
struct FrameRange {
  size_t first = 0;
  size_t last = 0;
};

// "A-B,C,...": ranges of frames, both ends included, or single frames (elo_eval --exclude-frames,
// tools/oxts_consistency.py --strays). Throws std::invalid_argument naming the item it cannot read.
std::vector<FrameRange> parseFrameRanges(const std::string& text);

// The segments that hold no frame of `excluded`: the metric over the stretches of a drive whose ground
// truth holds together (docs/real_drives.md: OXTS's direction of travel strays on parts of drive 0005).
std::vector<SegmentError> segmentsClearOf(const std::vector<SegmentError>& segments,
                                          const std::vector<FrameRange>& excluded);

// The mean over `segments`; the devkit's overall figure pools the segments of all sequences this way.
DriftError averageDrift(const std::vector<SegmentError>& segments);

// The mean for each segment length that has segments, in increasing length (the devkit's error plots).
std::vector<LengthDriftError> driftByLength(const std::vector<SegmentError>& segments);

}  // namespace elo
