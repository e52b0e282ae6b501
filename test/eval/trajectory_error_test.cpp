#include "elo/eval/trajectory_error.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>
#include <vector>

#include "elo/eval/evaluation.hpp"
#include "synthetic_trajectories.hpp"

namespace elo {
namespace {

TEST(TrajectoryError, GroundTruthAgainstItselfIsZero) {
  const std::vector<Eigen::Isometry3d> trajectory = test::circle(500, 1.2, 0.01);
  const RelativePoseError rpe = relativePoseError(trajectory, trajectory);
  EXPECT_EQ(rpe.pairs, 499u);
  EXPECT_NEAR(rpe.translation_rmse_m, 0.0, 1e-12);
  EXPECT_NEAR(rpe.rotation_rmse_deg, 0.0, 1e-9);
  EXPECT_NEAR(absoluteTrajectoryError(trajectory, trajectory).translation_rmse_m, 0.0, 1e-9);
}

TEST(TrajectoryError, RpeOfAConstantIncrementError) {
  // Every estimated increment moves 0.1 m further sideways and turns 0.5 deg more than the truth.
  const Eigen::Isometry3d true_step = test::translation(Eigen::Vector3d(1.0, 0, 0)) * test::yaw(0.01);
  const Eigen::Isometry3d step_error = test::translation(Eigen::Vector3d(0, 0.1, 0)) * test::yaw(0.5 * M_PI / 180.0);
  const RelativePoseError rpe =
      relativePoseError(test::chain(true_step, 200), test::chain(true_step * step_error, 200));
  EXPECT_NEAR(rpe.translation_rmse_m, 0.1, 1e-12);
  EXPECT_NEAR(rpe.rotation_rmse_deg, 0.5, 1e-9);
}

TEST(TrajectoryError, RigidlyTransformedEstimateHasZeroAteAfterAlignment) {
  const std::vector<Eigen::Isometry3d> ground_truth = test::circle(600, 1.0, 0.005);
  const Eigen::Isometry3d offset = test::translation(Eigen::Vector3d(30, -12, 4)) *
                                   Eigen::Isometry3d(Eigen::AngleAxisd(0.8, Eigen::Vector3d(1, 2, 3).normalized()));
  std::vector<Eigen::Isometry3d> estimate;
  for (const Eigen::Isometry3d& pose : ground_truth) estimate.push_back(offset * pose);
  const AbsoluteTrajectoryError ate = absoluteTrajectoryError(ground_truth, estimate);
  EXPECT_EQ(ate.frames, 600u);
  EXPECT_NEAR(ate.translation_rmse_m, 0.0, 1e-9);
  EXPECT_LT((ate.alignment.matrix() - offset.inverse().matrix()).topRows<3>().cwiseAbs().maxCoeff(), 1e-9);
}

TEST(TrajectoryError, AteIsTheRmsOfWhatAlignmentCannotRemove) {
  // Alternate frames are pushed +-d along z off a planar path: no rigid motion removes that, and the
  // optimal alignment leaves it in place (the offsets average to zero and are uncorrelated with the path).
  const std::vector<Eigen::Isometry3d> ground_truth = test::circle(400, 1.0, 0.0157);
  std::vector<Eigen::Isometry3d> estimate = ground_truth;
  const double d = 0.05;
  for (size_t i = 0; i < estimate.size(); ++i) estimate[i].translation().z() += (i % 2 == 0 ? d : -d);
  EXPECT_NEAR(absoluteTrajectoryError(ground_truth, estimate).translation_rmse_m, d, 1e-3 * d);
}

TEST(TrajectoryError, DifferentFrameCountsThrow) {
  EXPECT_THROW(relativePoseError(test::circle(5, 1, 0), test::circle(6, 1, 0)), std::invalid_argument);
  EXPECT_THROW(absoluteTrajectoryError(test::circle(5, 1, 0), test::circle(6, 1, 0)), std::invalid_argument);
}

// A run started mid-drive (elo_run --start) begins at the identity wherever the truth's pose is: the
// error of pose k compares the motions since each trajectory's first pose, whatever frame each is in.
TEST(PoseErrorFromFirst, ComparesTheMotionsSinceTheFirstPose) {
  const std::vector<Eigen::Isometry3d> ground_truth = test::circle(20, 1.0, 0.02);
  std::vector<Eigen::Isometry3d> estimate;
  for (const Eigen::Isometry3d& pose : ground_truth) estimate.push_back(ground_truth.front().inverse() * pose);
  // The estimate's pose 10 ends 0.3 m further along its own x and turned 2 deg more.
  estimate[10] = estimate[10] * test::translation(Eigen::Vector3d(0.3, 0, 0)) * test::yaw(2.0 * M_PI / 180.0);
  const Eigen::Isometry3d moved = test::translation(Eigen::Vector3d(40, -7, 3)) * test::yaw(1.1);
  std::vector<Eigen::Isometry3d> truth_elsewhere;
  for (const Eigen::Isometry3d& pose : ground_truth) truth_elsewhere.push_back(moved * pose);
  EXPECT_NEAR(poseErrorFromFirst(truth_elsewhere, estimate, 1).translation_m, 0.0, 1e-9);
  const PoseError error = poseErrorFromFirst(truth_elsewhere, estimate, 10);
  EXPECT_NEAR(error.translation_m, 0.3, 1e-9);
  EXPECT_NEAR(error.rotation_deg, 2.0, 1e-6);
  EXPECT_THROW(poseErrorFromFirst(ground_truth, estimate, 20), std::invalid_argument);
}

// The reverse run of a perfect odometry: scan n-1-j in scan n-1's frame.
std::vector<Eigen::Isometry3d> exactReverse(const std::vector<Eigen::Isometry3d>& forward) {
  std::vector<Eigen::Isometry3d> reverse;
  for (auto pose = forward.rbegin(); pose != forward.rend(); ++pose) reverse.push_back(forward.back().inverse() * *pose);
  return reverse;
}

TEST(ForwardBackwardGap, APerfectRoundTripCloses) {
  const std::vector<Eigen::Isometry3d> forward = test::circle(300, 0.8, 0.01);
  const ForwardBackwardGap gap = forwardBackwardGap(forward, exactReverse(forward));
  EXPECT_EQ(gap.frames, 300u);
  EXPECT_NEAR(gap.length_m, 299 * 0.8, 1e-9);
  EXPECT_NEAR(gap.translation_m, 0.0, 1e-9);
  EXPECT_NEAR(gap.rotation_deg, 0.0, 1e-6);
}

TEST(ForwardBackwardGap, MeasuresWhatTheReverseRunGotWrong) {
  // Straight ahead 99 m; the reverse run comes back 1% too far and ends turned by 0.5 deg.
  const std::vector<Eigen::Isometry3d> forward = test::circle(100, 1.0, 0.0);
  std::vector<Eigen::Isometry3d> reverse = test::circle(100, -1.01, 0.0);
  reverse.back() = reverse.back() * test::yaw(0.5 * M_PI / 180.0);
  const ForwardBackwardGap gap = forwardBackwardGap(forward, reverse);
  EXPECT_NEAR(gap.length_m, 99.0, 1e-9);
  EXPECT_NEAR(gap.translation_m, 0.99, 1e-9);
  EXPECT_NEAR(gap.rotation_deg, 0.5, 1e-9);
}

TEST(ForwardBackwardGap, RunsOverDifferentScansThrow) {
  const std::vector<Eigen::Isometry3d> forward = test::circle(10, 1.0, 0.0);
  EXPECT_THROW(forwardBackwardGap(forward, test::circle(9, -1.0, 0.0)), std::invalid_argument);
  EXPECT_THROW(forwardBackwardGap({}, {}), std::invalid_argument);
}

TEST(Evaluation, PoolingWeightsBySamples) {
  const std::vector<Eigen::Isometry3d> short_truth = test::straightLine(300, 1.0 + 1e-9);
  const std::vector<Eigen::Isometry3d> long_truth = test::circle(1200, 1.0, 0.001);
  const TrajectoryEvaluation exact = evaluateTrajectory("exact", short_truth, short_truth);
  const TrajectoryEvaluation drifting =
      evaluateTrajectory("drifting", long_truth, test::scaleIncrements(long_truth, 1.02));
  const TrajectoryEvaluation pooled = poolEvaluations("overall", {exact, drifting});

  EXPECT_EQ(pooled.frames, 1500u);
  EXPECT_NEAR(pooled.length_m, exact.length_m + drifting.length_m, 1e-9);
  EXPECT_EQ(pooled.drift.segments, exact.drift.segments + drifting.drift.segments);
  const double segment_weighted_t_rel =
      (drifting.drift.t_rel_percent * static_cast<double>(drifting.drift.segments)) /
      static_cast<double>(pooled.drift.segments);
  EXPECT_NEAR(pooled.drift.t_rel_percent, segment_weighted_t_rel, 1e-9);
  const double pair_weighted_rpe = std::sqrt(std::pow(drifting.rpe.translation_rmse_m, 2) * 1199.0 / 1498.0);
  EXPECT_NEAR(pooled.rpe.translation_rmse_m, pair_weighted_rpe, 1e-12);
  EXPECT_NEAR(drifting.rpe.translation_rmse_m, 0.02, 1e-9);
}

}  // namespace
}  // namespace elo
