#include "elo/eval/kitti_metric.hpp"

#include <algorithm>
#include <cmath>
#include <iterator>
#include <limits>
#include <optional>
#include <set>
#include <string>
#include <stdexcept>

#include "relative_motion.hpp"

namespace elo {
namespace {

using eval_detail::generalInverse;
using eval_detail::relativeMotion;

// The devkit's rotationError: the angle from the trace, clamped against rounding.
double devkitRotationAngle(const Eigen::Isometry3d& pose_error) {
  const double cos_angle = 0.5 * (pose_error.linear().trace() - 1.0);
  return std::acos(std::clamp(cos_angle, -1.0, 1.0));
}

// The devkit's lastFrameFromSegmentLength: the first frame whose distance exceeds the start's by more
// than `length`. The devkit scans linearly; distances never decrease, so a binary search finds the
// same frame.
std::optional<size_t> lastFrameOfSegment(const std::vector<double>& distances, size_t first_frame, double length) {
  const auto last = std::upper_bound(distances.begin() + static_cast<std::ptrdiff_t>(first_frame), distances.end(),
                                     distances[first_frame] + length);
  if (last == distances.end()) {
    return std::nullopt;
  }
  return static_cast<size_t>(last - distances.begin());
}

}  // namespace

const std::vector<double>& kittiSegmentLengths() {
  static const std::vector<double> lengths = {100, 200, 300, 400, 500, 600, 700, 800};
  return lengths;
}

std::vector<double> trajectoryDistances(const std::vector<Eigen::Isometry3d>& poses) {
  std::vector<double> distances(poses.size(), 0.0);
  for (size_t i = 1; i < poses.size(); ++i) {
    distances[i] = distances[i - 1] + (poses[i].translation() - poses[i - 1].translation()).norm();
  }
  return distances;
}

std::vector<SegmentError> kittiSegmentErrors(const std::vector<Eigen::Isometry3d>& ground_truth,
                                             const std::vector<Eigen::Isometry3d>& estimate,
                                             const std::vector<double>& lengths, size_t start_step) {
  eval_detail::requireSameLength(ground_truth, estimate);
  if (start_step == 0) throw std::invalid_argument("segments must start at least one frame apart");
  const std::vector<double> distances = trajectoryDistances(ground_truth);
  std::vector<SegmentError> segments;
  for (size_t first = 0; first < ground_truth.size(); first += start_step) {
    for (double length : lengths) {
      const std::optional<size_t> last = lastFrameOfSegment(distances, first, length);
      if (!last) {
        continue;
      }
      const Eigen::Isometry3d gt_motion = relativeMotion(ground_truth[first], ground_truth[*last]);
      const Eigen::Isometry3d estimated_motion = relativeMotion(estimate[first], estimate[*last]);
      const Eigen::Isometry3d pose_error = generalInverse(estimated_motion) * gt_motion;
      segments.push_back({first, *last, length, devkitRotationAngle(pose_error) / length,
                          pose_error.translation().norm() / length, pose_error.translation().head<2>().norm() / length});
    }
  }
  return segments;
}

std::vector<FrameRange> parseFrameRanges(const std::string& text) {
  const auto frame = [](const std::string& item, const std::string& number) {
    // At most 18 digits: a frame number, never past what size_t holds.
    const bool digits = !number.empty() && number.size() <= 18 &&
                        number.find_first_not_of("0123456789") == std::string::npos;
    if (!digits) throw std::invalid_argument("expected frames A-B or A, got '" + item + "'");
    return static_cast<size_t>(std::stoull(number));
  };
  std::vector<FrameRange> ranges;
  size_t begin = 0;
  while (begin <= text.size()) {
    const size_t comma = std::min(text.find(',', begin), text.size());
    const std::string item = text.substr(begin, comma - begin);
    const size_t dash = item.find('-');
    const size_t first = frame(item, item.substr(0, dash));
    const size_t last = dash == std::string::npos ? first : frame(item, item.substr(dash + 1));
    if (last < first) throw std::invalid_argument("expected A <= B in frames A-B, got '" + item + "'");
    ranges.push_back({first, last});
    begin = comma + 1;
  }
  return ranges;
}

std::vector<SegmentError> segmentsClearOf(const std::vector<SegmentError>& segments,
                                          const std::vector<FrameRange>& excluded) {
  const auto holds_excluded_frame = [&excluded](const SegmentError& segment) {
    return std::any_of(excluded.begin(), excluded.end(), [&segment](const FrameRange& range) {
      return range.first <= segment.last_frame && segment.first_frame <= range.last;
    });
  };
  std::vector<SegmentError> clear;
  std::remove_copy_if(segments.begin(), segments.end(), std::back_inserter(clear), holds_excluded_frame);
  return clear;
}

DriftError averageDrift(const std::vector<SegmentError>& segments) {
  DriftError drift;
  drift.segments = segments.size();
  if (segments.empty()) {
    drift.t_rel_percent = drift.r_rel_deg_per_100m = drift.t_rel_horizontal_percent =
        std::numeric_limits<double>::quiet_NaN();
    return drift;
  }
  double translation_sum = 0.0;
  double rotation_sum = 0.0;
  double horizontal_sum = 0.0;
  for (const SegmentError& segment : segments) {
    translation_sum += segment.translation_error;
    rotation_sum += segment.rotation_error;
    horizontal_sum += segment.horizontal_error;
  }
  const double count = static_cast<double>(segments.size());
  drift.t_rel_percent = 100.0 * translation_sum / count;
  drift.r_rel_deg_per_100m = 100.0 * (180.0 / M_PI) * rotation_sum / count;
  drift.t_rel_horizontal_percent = 100.0 * horizontal_sum / count;
  return drift;
}

std::vector<LengthDriftError> driftByLength(const std::vector<SegmentError>& segments) {
  std::set<double> lengths;
  for (const SegmentError& segment : segments) lengths.insert(segment.length);
  std::vector<LengthDriftError> result;
  for (double length : lengths) {
    std::vector<SegmentError> of_length;
    std::copy_if(segments.begin(), segments.end(), std::back_inserter(of_length),
                 [length](const SegmentError& segment) { return segment.length == length; });
    result.push_back({length, averageDrift(of_length)});
  }
  return result;
}

}  // namespace elo
