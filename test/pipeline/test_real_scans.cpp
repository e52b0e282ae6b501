// The whole pipeline on 60 real HDL-64E scans (../shared/data/real/hdl64_drive_a). There is no ground
// truth: the checks are that every scan is processed, the motion is plausible for a car at 10 Hz,
// frame-to-model and frame-to-frame agree, and runs forward and in reverse agree (Table III).
#include <gtest/gtest.h>

#include <filesystem>
#include <map>
#include <utility>

#include "elo/eval/kitti_metric.hpp"
#include "elo/eval/trajectory_error.hpp"
#include "elo/io/sequence.hpp"
#include "elo/pipeline/odometry.hpp"

namespace elo {
namespace {

const std::string kScans = std::string(ELO_SHARED_DATA) + "/real/hdl64_drive_a";

// The trajectory of the scans `played`, in their order, with `config` on 2 threads.
std::vector<Eigen::Isometry3d> runPlayed(const Sequence& sequence, const std::vector<PlayedScan>& played, Config config) {
  config.runtime.threads = 2;
  Odometry odometry(config);
  std::vector<Eigen::Isometry3d> poses;
  for (const PlayedScan& scan : played) {
    PointCloud cloud = sequence.load(scan.index);
    asPlayed(scan, cloud);
    const FrameResult result = odometry.process(cloud);
    EXPECT_TRUE(result.processed) << "scan " << scan.index << ": " << result.skip_reason;
    EXPECT_TRUE(result.pose.matrix().allFinite()) << "scan " << scan.index;
    poses.push_back(result.pose);
  }
  return poses;
}

std::vector<Eigen::Isometry3d> runSequence(const Sequence& sequence, RegistrationMode mode) {
  Config config;
  config.model.mode = mode;
  return runPlayed(sequence, playOrder(sequence, 1, false), config);
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
  const double length = trajectoryDistances(model).back();
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

TEST(RealScans, RangeAdaptiveNormalsKeepForwardAndReverseRunsClosestTogether) {
  // Every third scan: 1.1 m between scans, as at 40 km/h. Measured (forward-backward gap over 21 m):
  // range-adaptive 0.012 m / 0.019 deg, plain eigen 0.018 m / 0.020 deg, cross product 0.014 m / 0.006 deg.
  // Plain eigen's 2.8 m / 6.3 deg before the start search was a lost start, not drift; the cross product
  // drifted (0.21 m / 0.45 deg) until a ground patch of one scan ring stopped leaning (plane_fit.hpp).
  if (!std::filesystem::is_directory(kScans)) {
    GTEST_SKIP() << "real scans not found at " << kScans << " (shared data absent)";
  }
  const Sequence sequence(kScans);
  const std::vector<PlayedScan> forward = playOrder(sequence, 3, false);
  const std::vector<PlayedScan> reverse = playOrder(sequence, 3, true);
  const std::pair<NormalMethod, const char*> methods[] = {
      {NormalMethod::range_adaptive, "range-adaptive"}, {NormalMethod::eigen, "plain eigen"},
      {NormalMethod::cross_product, "cross product"}};
  std::map<NormalMethod, ForwardBackwardGap> gaps;
  for (const auto& [method, name] : methods) {
    Config config;
    config.normals.method = method;
    gaps[method] = forwardBackwardGap(runPlayed(sequence, forward, config), runPlayed(sequence, reverse, config));
    std::cout << name << ": forward-backward gap " << gaps[method].translation_m << " m, " << gaps[method].rotation_deg
              << " deg over " << gaps[method].length_m << " m" << std::endl;
  }
  const ForwardBackwardGap& adaptive = gaps[NormalMethod::range_adaptive];
  EXPECT_LT(adaptive.translation_m, 0.015);
  EXPECT_LT(adaptive.rotation_deg, 0.025);
  const ForwardBackwardGap& eigen = gaps[NormalMethod::eigen];
  EXPECT_GT(eigen.translation_m, 1.3 * adaptive.translation_m) << "plain eigen";
}

}  // namespace
}  // namespace elo
