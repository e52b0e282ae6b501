// The whole pipeline on 60 real HDL-64E scans (../shared/data/real/hdl64_drive_a). There is no ground
// truth: the checks are that every scan is processed, the motion is plausible for a car at 10 Hz, and
// frame-to-model and frame-to-frame agree.
#include <gtest/gtest.h>

#include <filesystem>

#include "elo/io/sequence.hpp"
#include "elo/odometry.hpp"

namespace elo {
namespace {

const std::string kScans = std::string(ELO_SHARED_DATA) + "/real/hdl64_drive_a";

std::vector<Eigen::Isometry3d> runSequence(const Sequence& sequence, RegistrationMode mode) {
  Config config;
  config.model.mode = mode;
  config.runtime.threads = 2;
  Odometry odometry(config);
  std::vector<Eigen::Isometry3d> poses;
  for (size_t i = 0; i < sequence.size(); ++i) {
    const FrameResult result = odometry.process(sequence.load(i));
    EXPECT_TRUE(result.processed) << "scan " << i << ": " << result.skip_reason;
    EXPECT_TRUE(result.pose.matrix().allFinite()) << "scan " << i;
    poses.push_back(result.pose);
  }
  return poses;
}

double pathLength(const std::vector<Eigen::Isometry3d>& poses) {
  double length = 0.0;
  for (size_t i = 1; i < poses.size(); ++i) length += (poses[i].translation() - poses[i - 1].translation()).norm();
  return length;
}

TEST(RealScans, BothModesTrackTheDriveAndAgree) {
  if (!std::filesystem::is_directory(kScans)) {
    GTEST_SKIP() << "real scans not found at " << kScans << " (shared data absent)";
  }
  const Sequence sequence(kScans);
  ASSERT_EQ(sequence.size(), 60u);
  const std::vector<Eigen::Isometry3d> model = runSequence(sequence, RegistrationMode::frame_to_model);
  const std::vector<Eigen::Isometry3d> frame = runSequence(sequence, RegistrationMode::frame_to_frame);
  for (size_t i = 1; i < model.size(); ++i) {
    const double step = (model[i - 1].inverse() * model[i]).translation().norm();
    EXPECT_GE(step, 0.2) << "scan " << i;
    EXPECT_LE(step, 1.0) << "scan " << i;
  }
  const double length = pathLength(model);
  EXPECT_GT(length, 15.0);
  EXPECT_LT(length, 45.0);
  double worst = 0.0;
  for (size_t i = 0; i < model.size(); ++i) {
    worst = std::max(worst, (model[i].translation() - frame[i].translation()).norm());
  }
  std::cout << "path " << length << " m, largest frame-to-model / frame-to-frame gap " << worst << " m ("
            << 100.0 * worst / length << " %)" << std::endl;
  EXPECT_LT(worst, 0.02 * length);
}

}  // namespace
}  // namespace elo
