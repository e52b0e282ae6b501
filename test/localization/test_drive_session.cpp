// The drive session (elo/drive_session.hpp), the one place a scan goes through after it is read, under
// the node and elo_run: on a short simulated drive it gives the odometry's poses to the bit and the map a
// hand-fed MapBuilder gets, localizes in a map of the drive, and passes skips, restarts and refusals of
// its inputs through to its counts and its trajectory.
#include <gtest/gtest.h>

#include <memory>

#include "elo/drive_session.hpp"
#include "elo/sim/sensors.hpp"
#include "shared_world.hpp"

namespace elo {
namespace {

using test::Drive;
using test::DrivePlan;
using test::SharedWorld;

constexpr int kFrames = 15;

Config hdl64() {
  Config config;
  sim::loadSensor("hdl64", config);
  return config;
}

class DriveSessionTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    world_ = std::make_unique<SharedWorld>(sim::WorldFamily::urban, sim::TrajectoryKind::curves, 10.0, 7);
    drive_ = std::make_unique<Drive>(*world_, hdl64(), DrivePlan{0.0, 0.0, 11, 1});
    for (int frame = 0; frame < kFrames; ++frame) scans_.push_back(drive_->scan(frame));
  }
  static void TearDownTestSuite() {
    scans_.clear();
    drive_.reset();
    world_.reset();
  }

  static std::unique_ptr<SharedWorld> world_;
  static std::unique_ptr<Drive> drive_;
  static std::vector<PointCloud> scans_;
};
std::unique_ptr<SharedWorld> DriveSessionTest::world_;
std::unique_ptr<Drive> DriveSessionTest::drive_;
std::vector<PointCloud> DriveSessionTest::scans_;

bool sameMap(const MapCloud& a, const MapCloud& b) {
  return a.points == b.points && a.normals == b.normals && a.intensity == b.intensity;
}

TEST_F(DriveSessionTest, GivesTheOdometrysPosesAndTheMapAHandFedBuilderGets) {
  DriveSessionOptions options;
  options.build_map = true;
  DriveSession session(hdl64(), options);
  Odometry odometry(hdl64());
  MapBuilder builder(hdl64().map);
  for (const PointCloud& scan : scans_) {
    const DriveStep step = session.process(scan);
    const FrameResult direct = odometry.process(scan);
    ASSERT_TRUE(step.odometry.processed);
    EXPECT_TRUE(step.odometry.pose.matrix() == direct.pose.matrix()) << "scan at " << scan.stamp;
    session.feedMap(step, scan);
    if (builder.takesNextScan()) {
      builder.add(mapScanOf(odometry.backend().scan(), scan, odometry.modelPose(), scan.stamp, hdl64().map.voxel_size));
    }
  }
  const DriveTrajectory trajectory = session.trajectory();
  ASSERT_EQ(trajectory.odometry.size(), scans_.size());
  EXPECT_TRUE(trajectory.odometry.back().matrix() == odometry.pose().matrix());
  EXPECT_EQ(trajectory.stamps.back(), scans_.back().stamp);
  EXPECT_TRUE(trajectory.in_map.empty());
  EXPECT_EQ(session.mapFeedStatistics().processed, scans_.size());
  EXPECT_GT(session.driveMap()->statistics().scans, 0u);
  EXPECT_TRUE(sameMap(session.driveMap()->points(), builder.points()));
}

TEST_F(DriveSessionTest, LocalizesInAMapOfTheDrive) {
  const Config config = hdl64();
  auto map = std::make_shared<MapCloud>(
      test::mapOfDrive(*drive_, kFrames, 1, 0.2, config.localization.normal_radius));
  DriveSession session(config);
  session.localizeIn(map, drive_->pose(0));
  for (int frame = 0; frame < kFrames; ++frame) {
    const DriveStep step = session.process(scans_[frame]);
    ASSERT_TRUE(step.localization) << step.localization_failure;
    EXPECT_EQ(step.localization->state, LocalizationState::tracking) << "scan " << frame;
    const double error = (step.localization->pose.translation() - drive_->pose(frame).translation()).norm();
    EXPECT_LT(error, 0.1) << "scan " << frame;
  }
  const DriveTrajectory trajectory = session.trajectory();
  ASSERT_EQ(trajectory.in_map.size(), static_cast<size_t>(kFrames));
  EXPECT_LT((trajectory.in_map.back().translation() - drive_->pose(kFrames - 1).translation()).norm(), 0.1);
  EXPECT_GT(session.localizer()->acceptedCount(), static_cast<size_t>(kFrames) / 2);
}

TEST_F(DriveSessionTest, SkipsAndRestartsFlowIntoItsCountsAndTrajectory) {
  DriveSessionOptions options;
  options.build_map = true;
  options.trajectory_restarts = true;
  DriveSession session(hdl64(), options);
  ASSERT_TRUE(session.process(scans_[0]).odometry.processed);
  const DriveStep second = session.process(scans_[1]);
  ASSERT_TRUE(second.odometry.processed);
  EXPECT_NEAR(second.since_last_processed, scans_[1].stamp - scans_[0].stamp, 1e-12);

  // Unreadable before the odometry, then unusable to it: both lines repeat the last pose, each counted.
  const DriveStep unreadable = session.skipUnreadable(scans_[2].stamp, "truncated file");
  EXPECT_FALSE(unreadable.odometry.processed);
  EXPECT_TRUE(unreadable.odometry.pose.matrix() == second.odometry.pose.matrix());
  EXPECT_EQ(session.unreadableCounts().at("truncated file"), 1u);
  PointCloud empty;
  empty.stamp = scans_[3].stamp;
  const DriveStep unusable = session.process(empty);
  EXPECT_FALSE(unusable.odometry.processed);
  EXPECT_EQ(session.odometry().skippedCounts().size(), 1u);
  EXPECT_EQ(session.feedMap(unusable, empty), DriveSession::MapFeed::left_out);
  EXPECT_EQ(session.trajectory().odometry.size(), 4u);

  // A reset: the next scan starts a trajectory of its own, and a scan from before it stays out of the map.
  session.reset();
  const DriveStep after = session.process(scans_[4]);
  EXPECT_TRUE(after.restarted);
  EXPECT_EQ(after.since_last_processed, 0.0);
  EXPECT_TRUE(after.odometry.pose.matrix() == Eigen::Isometry3d::Identity().matrix());
  EXPECT_EQ(session.trajectory().odometry.size(), 1u);
  EXPECT_EQ(session.feedMap(second, scans_[1]), DriveSession::MapFeed::left_out);
  EXPECT_EQ(session.feedMap(after, scans_[4]), DriveSession::MapFeed::queued);

  // Time going backwards restarts it too, told on the scan that found it.
  const DriveStep backwards = session.process(scans_[2]);
  EXPECT_TRUE(backwards.odometry.reset);
  EXPECT_TRUE(backwards.restarted);
  EXPECT_EQ(session.trajectory().odometry.size(), 1u);
}

TEST_F(DriveSessionTest, KeepsEveryLineWhenTheTrajectoryDoesNotRestart) {
  DriveSession session(hdl64());
  session.process(scans_[0]);
  session.process(scans_[1]);
  session.reset();
  const DriveStep after = session.process(scans_[2]);
  EXPECT_TRUE(after.restarted);
  EXPECT_EQ(session.trajectory().odometry.size(), 3u);
}

TEST(PoseFromXyzYaw, TurnsAboutZInDegrees) {
  const Eigen::Isometry3d pose = poseFromXyzYaw({1.0, 2.0, 3.0, 90.0});
  EXPECT_TRUE(pose.translation().isApprox(Eigen::Vector3d(1.0, 2.0, 3.0)));
  EXPECT_TRUE((pose.rotation() * Eigen::Vector3d::UnitX()).isApprox(Eigen::Vector3d::UnitY(), 1e-12));
  EXPECT_THROW(poseFromXyzYaw({1.0, 2.0, 3.0}), std::invalid_argument);
}

}  // namespace
}  // namespace elo
