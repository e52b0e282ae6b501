#include "elo/eval/error_breakdown.hpp"

#include <cmath>
#include <limits>

#include "relative_motion.hpp"

namespace elo {
namespace {

using eval_detail::generalInverse;
using eval_detail::relativeMotion;

// Forward (the ground truth's chord), left (horizontal, across it) and up (perpendicular to both) in the
// frame of the segment's last pose. `gt_motion` maps that frame into the first pose's frame, so the
// chord from first to last, seen from the last frame, is its rotation's inverse applied to its
// translation. A chord straight up (no horizontal part) takes the frame's own left.
Eigen::Matrix3d travelAxes(const Eigen::Isometry3d& gt_motion) {
  const Eigen::Vector3d chord = gt_motion.linear().inverse() * gt_motion.translation();
  const Eigen::Vector3d forward = chord.norm() > 0.0 ? chord.normalized() : Eigen::Vector3d::UnitX();
  Eigen::Vector3d left = Eigen::Vector3d::UnitZ().cross(forward);
  left = left.norm() > 1e-9 ? left.normalized() : Eigen::Vector3d::UnitY();
  Eigen::Matrix3d axes;
  axes << forward, left, forward.cross(left);
  return axes;
}

SegmentComponents componentsOf(const Eigen::Isometry3d& gt_motion, const Eigen::Isometry3d& estimated_motion,
                               double length) {
  const Eigen::Isometry3d error = generalInverse(gt_motion) * estimated_motion;
  // The rotation vector: for the small angles of odometry error, the angles about each axis.
  const Eigen::AngleAxisd rotation(Eigen::Quaterniond(error.linear()).normalized());
  const Eigen::Vector3d angles = rotation.angle() * rotation.axis();
  const Eigen::Vector3d offset = travelAxes(gt_motion).transpose() * error.translation();
  return {angles.z() / length, angles.y() / length, angles.x() / length,
          offset.x() / length, offset.y() / length, offset.z() / length};
}

}  // namespace

std::vector<SegmentComponents> segmentComponents(const std::vector<Eigen::Isometry3d>& ground_truth,
                                                 const std::vector<Eigen::Isometry3d>& estimate,
                                                 const std::vector<SegmentError>& segments) {
  eval_detail::requireSameLength(ground_truth, estimate);
  std::vector<SegmentComponents> components;
  components.reserve(segments.size());
  for (const SegmentError& segment : segments) {
    components.push_back(
        componentsOf(relativeMotion(ground_truth[segment.first_frame], ground_truth[segment.last_frame]),
                     relativeMotion(estimate[segment.first_frame], estimate[segment.last_frame]), segment.length));
  }
  return components;
}

ErrorBreakdown averageBreakdown(const std::vector<SegmentComponents>& components) {
  ErrorBreakdown breakdown;
  breakdown.segments = components.size();
  if (components.empty()) {
    const double nan = std::numeric_limits<double>::quiet_NaN();
    return {0, nan, nan, nan, nan, nan, nan};
  }
  for (const SegmentComponents& segment : components) {
    breakdown.heading_deg_per_100m += std::abs(segment.yaw);
    breakdown.pitch_deg_per_100m += std::abs(segment.pitch);
    breakdown.roll_deg_per_100m += std::abs(segment.roll);
    breakdown.along_track_percent += segment.along;
    breakdown.cross_track_percent += std::abs(segment.cross);
    breakdown.height_percent += std::abs(segment.height);
  }
  const double degrees_per_100m = 100.0 * (180.0 / M_PI) / static_cast<double>(components.size());
  const double percent = 100.0 / static_cast<double>(components.size());
  breakdown.heading_deg_per_100m *= degrees_per_100m;
  breakdown.pitch_deg_per_100m *= degrees_per_100m;
  breakdown.roll_deg_per_100m *= degrees_per_100m;
  breakdown.along_track_percent *= percent;
  breakdown.cross_track_percent *= percent;
  breakdown.height_percent *= percent;
  return breakdown;
}

}  // namespace elo
