// GCC 12 reports a false -Warray-bounds inside the AVX loads that Eigen::umeyama instantiates under
// -march=native; it points into Eigen, so it is silenced here, before the Eigen headers.
#pragma GCC diagnostic ignored "-Warray-bounds"
#include "elo/eval/trajectory_error.hpp"

#include <Eigen/Geometry>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "elo/eval/kitti_metric.hpp"
#include "relative_motion.hpp"

namespace elo {
namespace {

constexpr double kNoData = std::numeric_limits<double>::quiet_NaN();

// Through a quaternion rather than the trace: accurate for the small angles of one frame's motion.
double rotationAngleDeg(const Eigen::Matrix3d& rotation) {
  return Eigen::AngleAxisd(Eigen::Quaterniond(rotation).normalized()).angle() * 180.0 / M_PI;
}

Eigen::Matrix3Xd positions(const std::vector<Eigen::Isometry3d>& poses) {
  Eigen::Matrix3Xd result(3, static_cast<Eigen::Index>(poses.size()));
  for (size_t i = 0; i < poses.size(); ++i) {
    result.col(static_cast<Eigen::Index>(i)) = poses[i].translation();
  }
  return result;
}

}  // namespace

RelativePoseError relativePoseError(const std::vector<Eigen::Isometry3d>& ground_truth,
                                    const std::vector<Eigen::Isometry3d>& estimate) {
  eval_detail::requireSameLength(ground_truth, estimate);
  RelativePoseError rpe;
  rpe.pairs = ground_truth.empty() ? 0 : ground_truth.size() - 1;
  if (rpe.pairs == 0) {
    rpe.translation_rmse_m = rpe.rotation_rmse_deg = kNoData;
    return rpe;
  }
  double translation_squares = 0.0;
  double rotation_squares = 0.0;
  for (size_t i = 0; i + 1 < ground_truth.size(); ++i) {
    const Eigen::Isometry3d gt_motion = eval_detail::relativeMotion(ground_truth[i], ground_truth[i + 1]);
    const Eigen::Isometry3d estimated_motion = eval_detail::relativeMotion(estimate[i], estimate[i + 1]);
    const Eigen::Isometry3d error = eval_detail::generalInverse(gt_motion) * estimated_motion;
    translation_squares += error.translation().squaredNorm();
    rotation_squares += std::pow(rotationAngleDeg(error.linear()), 2);
  }
  rpe.translation_rmse_m = std::sqrt(translation_squares / static_cast<double>(rpe.pairs));
  rpe.rotation_rmse_deg = std::sqrt(rotation_squares / static_cast<double>(rpe.pairs));
  return rpe;
}

AbsoluteTrajectoryError absoluteTrajectoryError(const std::vector<Eigen::Isometry3d>& ground_truth,
                                                const std::vector<Eigen::Isometry3d>& estimate) {
  eval_detail::requireSameLength(ground_truth, estimate);
  AbsoluteTrajectoryError ate;
  ate.frames = ground_truth.size();
  if (ate.frames == 0) {
    ate.translation_rmse_m = kNoData;
    return ate;
  }
  const Eigen::Matrix3Xd gt_positions = positions(ground_truth);
  const Eigen::Matrix3Xd estimated_positions = positions(estimate);
  ate.alignment.matrix() = Eigen::umeyama(estimated_positions, gt_positions, /*with_scaling=*/false);
  const Eigen::Matrix3Xd residuals = (ate.alignment * estimated_positions) - gt_positions;
  ate.translation_rmse_m = std::sqrt(residuals.colwise().squaredNorm().mean());
  return ate;
}

PoseError poseErrorFromFirst(const std::vector<Eigen::Isometry3d>& ground_truth,
                             const std::vector<Eigen::Isometry3d>& estimate, size_t frame) {
  if (frame >= ground_truth.size() || frame >= estimate.size()) {
    throw std::invalid_argument("pose " + std::to_string(frame) + " asked of trajectories of " +
                                std::to_string(ground_truth.size()) + " and " + std::to_string(estimate.size()) +
                                " poses");
  }
  const Eigen::Isometry3d error =
      eval_detail::generalInverse(eval_detail::relativeMotion(ground_truth.front(), ground_truth[frame])) *
      eval_detail::relativeMotion(estimate.front(), estimate[frame]);
  return {error.translation().norm(), rotationAngleDeg(error.linear())};
}

ForwardBackwardGap forwardBackwardGap(const std::vector<Eigen::Isometry3d>& forward,
                                      const std::vector<Eigen::Isometry3d>& reverse) {
  if (forward.empty() || forward.size() != reverse.size()) {
    throw std::invalid_argument("the forward run has " + std::to_string(forward.size()) +
                                " poses and the reverse run " + std::to_string(reverse.size()) +
                                ": they must cover the same scans");
  }
  const Eigen::Isometry3d round_trip = forward.back() * reverse.back();
  ForwardBackwardGap gap;
  gap.frames = forward.size();
  gap.length_m = trajectoryDistances(forward).back();
  gap.translation_m = round_trip.translation().norm();
  gap.rotation_deg = rotationAngleDeg(round_trip.linear());
  return gap;
}

}  // namespace elo
