// The metric on the official KITTI ground truth, against an independent transcription of the devkit.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

#include "elo/eval/evaluation.hpp"
#include "elo/io/kitti.hpp"
#include "synthetic_trajectories.hpp"

namespace elo {
namespace {

namespace fs = std::filesystem;

fs::path posesDirectory() { return fs::path(ELO_SHARED_DATA) / "kitti_gt" / "poses"; }

// The devkit's calcSequenceErrors (evaluate_odometry.cpp) as written there: float distances and
// lengths, a linear search for the last frame, double matrices with a general inverse.
struct DevkitResult {
  size_t segments = 0;
  double t_err_sum = 0.0;  // sums of the per-metre errors
  double r_err_sum = 0.0;
};

DevkitResult devkitSequenceErrors(const std::vector<Eigen::Isometry3d>& poses_gt,
                                  const std::vector<Eigen::Isometry3d>& poses_result) {
  const float lengths[] = {100, 200, 300, 400, 500, 600, 700, 800};
  std::vector<float> dist{0.0f};
  for (size_t i = 1; i < poses_gt.size(); ++i) {
    const Eigen::Vector3d d = poses_gt[i - 1].translation() - poses_gt[i].translation();
    const float dx = static_cast<float>(d.x()), dy = static_cast<float>(d.y()), dz = static_cast<float>(d.z());
    dist.push_back(dist[i - 1] + std::sqrt(dx * dx + dy * dy + dz * dz));
  }
  DevkitResult result;
  for (size_t first_frame = 0; first_frame < poses_gt.size(); first_frame += 10) {
    for (float len : lengths) {
      int64_t last_frame = -1;
      for (size_t i = first_frame; i < dist.size(); ++i) {
        if (dist[i] > dist[first_frame] + len) {
          last_frame = static_cast<int64_t>(i);
          break;
        }
      }
      if (last_frame == -1) continue;
      const Eigen::Matrix4d delta_gt = poses_gt[first_frame].matrix().inverse() * poses_gt[last_frame].matrix();
      const Eigen::Matrix4d delta_result =
          poses_result[first_frame].matrix().inverse() * poses_result[last_frame].matrix();
      const Eigen::Matrix4d pose_error = delta_result.inverse() * delta_gt;
      const double d = 0.5 * (pose_error(0, 0) + pose_error(1, 1) + pose_error(2, 2) - 1.0);
      result.r_err_sum += std::acos(std::max(std::min(d, 1.0), -1.0)) / len;
      result.t_err_sum += pose_error.block<3, 1>(0, 3).norm() / len;
      ++result.segments;
    }
  }
  return result;
}

// A plausible odometry: 1% long, and drifting in yaw by 0.001 deg a frame.
std::vector<Eigen::Isometry3d> perturbed(const std::vector<Eigen::Isometry3d>& ground_truth) {
  std::vector<Eigen::Isometry3d> estimate = test::scaleIncrements(ground_truth, 1.01);
  for (size_t i = 0; i < estimate.size(); ++i) {
    // KITTI poses are in the camera frame: y points down, so yaw turns about y.
    estimate[i] = estimate[i] * Eigen::Isometry3d(Eigen::AngleAxisd(1.745e-5 * static_cast<double>(i),
                                                                    Eigen::Vector3d::UnitY()));
  }
  return estimate;
}

std::vector<fs::path> groundTruthFiles() {
  std::vector<fs::path> files;
  if (fs::is_directory(posesDirectory())) {
    for (const fs::directory_entry& entry : fs::directory_iterator(posesDirectory())) files.push_back(entry.path());
  }
  std::sort(files.begin(), files.end());
  return files;
}

TEST(RealTrajectories, EachAgainstItselfIsZero) {
  const std::vector<fs::path> files = groundTruthFiles();
  if (files.empty()) GTEST_SKIP() << "shared data absent: " << posesDirectory();
  for (const fs::path& file : files) {
    const std::vector<Eigen::Isometry3d> poses = readKittiPoses(file.string());
    const TrajectoryEvaluation evaluation = evaluateTrajectory(file.stem().string(), poses, poses);
    EXPECT_GT(evaluation.drift.segments, 0u) << file;
    EXPECT_NEAR(evaluation.drift.t_rel_percent, 0.0, 1e-9) << file;
    EXPECT_NEAR(evaluation.drift.r_rel_deg_per_100m, 0.0, 1e-5) << file;
    EXPECT_NEAR(evaluation.rpe.translation_rmse_m, 0.0, 1e-9) << file;
    EXPECT_NEAR(evaluation.rpe.rotation_rmse_deg, 0.0, 1e-6) << file;
    EXPECT_NEAR(evaluation.ate.translation_rmse_m, 0.0, 1e-6) << file;
  }
}

TEST(RealTrajectories, EachAgainstAPerturbedCopyIsPositive) {
  const std::vector<fs::path> files = groundTruthFiles();
  if (files.empty()) GTEST_SKIP() << "shared data absent: " << posesDirectory();
  std::vector<TrajectoryEvaluation> evaluations;
  for (const fs::path& file : files) {
    const std::vector<Eigen::Isometry3d> poses = readKittiPoses(file.string());
    evaluations.push_back(evaluateTrajectory(file.stem().string(), poses, perturbed(poses)));
    const TrajectoryEvaluation& evaluation = evaluations.back();
    for (double value : {evaluation.drift.t_rel_percent, evaluation.drift.r_rel_deg_per_100m,
                         evaluation.rpe.translation_rmse_m, evaluation.rpe.rotation_rmse_deg,
                         evaluation.ate.translation_rmse_m}) {
      EXPECT_TRUE(std::isfinite(value) && value > 0.0) << file << ": " << value;
    }
  }
  const TrajectoryEvaluation overall = poolEvaluations("overall", evaluations);
  EXPECT_EQ(overall.frames, 23201u);
  EXPECT_TRUE(std::isfinite(overall.drift.t_rel_percent));
}

TEST(RealTrajectories, Sequence00MatchesTheDevkit) {
  const fs::path file = posesDirectory() / "00.txt";
  if (!fs::exists(file)) GTEST_SKIP() << "shared data absent: " << file;
  const std::vector<Eigen::Isometry3d> ground_truth = readKittiPoses(file.string());
  const std::vector<Eigen::Isometry3d> estimate = perturbed(ground_truth);

  const DevkitResult devkit = devkitSequenceErrors(ground_truth, estimate);
  const DriftError drift = averageDrift(kittiSegmentErrors(ground_truth, estimate));
  ASSERT_EQ(drift.segments, devkit.segments);
  // The devkit's float distances (a float spacing of ~2e-4 m at 4 km) can end a few segments one frame
  // later or earlier than double distances do, so the means agree closely but not to the last digit.
  const double count = static_cast<double>(devkit.segments);
  EXPECT_NEAR(drift.t_rel_percent, 100.0 * devkit.t_err_sum / count, 1e-4 * drift.t_rel_percent);
  EXPECT_NEAR(drift.r_rel_deg_per_100m, 100.0 * 180.0 / M_PI * devkit.r_err_sum / count,
              1e-4 * drift.r_rel_deg_per_100m);
}

}  // namespace
}  // namespace elo
