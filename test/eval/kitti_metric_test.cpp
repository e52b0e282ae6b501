#include "elo/eval/kitti_metric.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "synthetic_trajectories.hpp"

namespace elo {
namespace {

// Slightly over 1 m a frame, so that a segment of L metres ends exactly L frames after its start (at
// exactly 1 m, "exceeds" would need L + 1 frames and the chord would not be L).
constexpr double kSpacing = 1.0 + 1e-9;
constexpr size_t kFrames = 1000;

TEST(KittiMetric, TrajectoryDistancesAccumulate) {
  const std::vector<double> distances = trajectoryDistances(test::straightLine(4, 2.5));
  ASSERT_EQ(distances.size(), 4u);
  EXPECT_EQ(distances[0], 0.0);
  EXPECT_NEAR(distances[3], 7.5, 1e-12);
}

TEST(KittiMetric, GroundTruthAgainstItselfIsZero) {
  for (const auto& trajectory : {test::straightLine(kFrames, kSpacing), test::circle(kFrames, 1.3, 0.003)}) {
    const DriftError drift = averageDrift(kittiSegmentErrors(trajectory, trajectory));
    EXPECT_GT(drift.segments, 0u);
    EXPECT_NEAR(drift.t_rel_percent, 0.0, 1e-12);
    // The devkit's acos of the trace resolves angles only down to ~1.5e-8 rad.
    EXPECT_NEAR(drift.r_rel_deg_per_100m, 0.0, 1e-5);
  }
}

TEST(KittiMetric, SegmentsFollowTheDevkitDefinition) {
  const std::vector<SegmentError> segments = kittiSegmentErrors(test::straightLine(kFrames, kSpacing),
                                                                test::straightLine(kFrames, kSpacing));
  // Starts every 10 frames; a segment of L m needs frame start + L, which exists while start + L < 1000.
  size_t expected = 0;
  for (size_t first = 0; first < kFrames; first += 10) {
    for (double length : kittiSegmentLengths()) expected += first + static_cast<size_t>(length) < kFrames ? 1 : 0;
  }
  EXPECT_EQ(segments.size(), expected);
  for (const SegmentError& segment : segments) {
    EXPECT_EQ(segment.first_frame % 10, 0u);
    EXPECT_EQ(segment.last_frame - segment.first_frame, static_cast<size_t>(segment.length));
  }
}

// Short drives are scored over shorter segments (docs/real_drives.md: 10..100 m); the starts keep the
// devkit's step of 10 frames, and the errors by length follow the lengths asked for.
TEST(KittiMetric, SegmentLengthsAreTheCallersChoice) {
  const std::vector<Eigen::Isometry3d> ground_truth = test::straightLine(kFrames, kSpacing);
  const std::vector<SegmentError> segments =
      kittiSegmentErrors(ground_truth, test::scaleIncrements(ground_truth, 1.01), {10, 50});
  size_t expected = 0;
  for (size_t first = 0; first < kFrames; first += 10) expected += (first + 10 < kFrames) + (first + 50 < kFrames);
  EXPECT_EQ(segments.size(), expected);
  for (const SegmentError& segment : segments) {
    EXPECT_EQ(segment.first_frame % 10, 0u);
    EXPECT_EQ(segment.last_frame - segment.first_frame, static_cast<size_t>(segment.length));
  }
  const std::vector<LengthDriftError> by_length = driftByLength(segments);
  ASSERT_EQ(by_length.size(), 2u);
  EXPECT_EQ(by_length[0].length, 10.0);
  EXPECT_EQ(by_length[1].length, 50.0);
  EXPECT_NEAR(by_length[0].error.t_rel_percent, 1.0, 1e-6);
}

// A short drive is scored with a segment starting at every frame (elo_eval --segment-step 1).
TEST(KittiMetric, SegmentStartsAreTheCallersChoice) {
  const std::vector<Eigen::Isometry3d> ground_truth = test::straightLine(kFrames, kSpacing);
  const std::vector<SegmentError> segments =
      kittiSegmentErrors(ground_truth, test::scaleIncrements(ground_truth, 1.01), {10}, 1);
  ASSERT_EQ(segments.size(), kFrames - 10);
  for (size_t i = 0; i < segments.size(); ++i) EXPECT_EQ(segments[i].first_frame, i);
  EXPECT_NEAR(averageDrift(segments).t_rel_percent, 1.0, 1e-6);
  EXPECT_THROW(kittiSegmentErrors(ground_truth, ground_truth, {10}, 0), std::invalid_argument);
}

// A ground truth that strays 0.5 m sideways over frames 400-449 while the estimate drives straight on:
// the segments holding one of those frames are left out, and the others score nothing.
TEST(KittiMetric, SegmentsClearOfExcludedFramesLeaveAStrayingGroundTruthOut) {
  const std::vector<Eigen::Isometry3d> estimate = test::straightLine(kFrames, kSpacing);
  std::vector<Eigen::Isometry3d> ground_truth = estimate;
  for (size_t i = 400; i < 450; ++i) ground_truth[i].translation().y() += 0.5;
  const std::vector<SegmentError> segments = kittiSegmentErrors(ground_truth, estimate, {10}, 1);
  EXPECT_GT(averageDrift(segments).t_rel_percent, 0.1);
  const std::vector<SegmentError> clear = segmentsClearOf(segments, {{400, 449}});
  EXPECT_NEAR(averageDrift(clear).t_rel_percent, 0.0, 1e-9);
  const auto kept = [&clear](size_t first) {
    return std::any_of(clear.begin(), clear.end(), [first](const SegmentError& s) { return s.first_frame == first; });
  };
  EXPECT_TRUE(kept(389)) << "frames 389-399";
  EXPECT_FALSE(kept(390)) << "frames 390-400";
  EXPECT_FALSE(kept(449));
  EXPECT_TRUE(kept(450));
  // 10 m segments starting at every frame before the last 10: those starting 390-449 are left out.
  EXPECT_EQ(clear.size(), segments.size() - 60);
  EXPECT_EQ(segmentsClearOf(segments, {}).size(), segments.size());
  EXPECT_EQ(segmentsClearOf(segments, {{0, kFrames}}).size(), 0u);
  EXPECT_TRUE(std::isnan(averageDrift(segmentsClearOf(segments, {{0, kFrames}})).t_rel_percent));
}

TEST(KittiMetric, FrameRangesAreReadFromText) {
  const std::vector<FrameRange> ranges = parseFrameRanges("0-30,32,48-88");
  ASSERT_EQ(ranges.size(), 3u);
  EXPECT_EQ(ranges[0].first, 0u);
  EXPECT_EQ(ranges[0].last, 30u);
  EXPECT_EQ(ranges[1].first, 32u);
  EXPECT_EQ(ranges[1].last, 32u);
  EXPECT_EQ(ranges[2].first, 48u);
  EXPECT_EQ(ranges[2].last, 88u);
  for (const char* bad : {"", "5-3", "x", "1-", "-1", "1,,2", "1 -2", "+1", "1234567890123456789012"}) {
    EXPECT_THROW(parseFrameRanges(bad), std::invalid_argument) << bad;
  }
}

TEST(KittiMetric, ScaledIncrementsOnAStraightLineGiveOnePercent) {
  const std::vector<Eigen::Isometry3d> ground_truth = test::straightLine(kFrames, kSpacing);
  const std::vector<SegmentError> segments =
      kittiSegmentErrors(ground_truth, test::scaleIncrements(ground_truth, 1.01));
  const DriftError drift = averageDrift(segments);
  EXPECT_NEAR(drift.t_rel_percent, 1.0, 1e-6);
  EXPECT_NEAR(drift.r_rel_deg_per_100m, 0.0, 1e-5);
  const std::vector<LengthDriftError> by_length = driftByLength(segments);
  ASSERT_EQ(by_length.size(), 8u);
  for (const LengthDriftError& entry : by_length) {
    EXPECT_NEAR(entry.error.t_rel_percent, 1.0, 1e-6) << entry.length << " m";
  }
}

// The horizontal part tells a drift in the plane from one in height: an estimate that climbs 1 cm a metre
// while the truth drives level has a t_rel of 1% and no horizontal drift; one 1% long along the road has
// both at 1%.
TEST(KittiMetric, HorizontalDriftLeavesOutTheHeight) {
  const std::vector<Eigen::Isometry3d> ground_truth =
      test::chain(test::translation(Eigen::Vector3d(kSpacing, 0.0, 0.0)), kFrames);  // level, along x
  std::vector<Eigen::Isometry3d> climbing = ground_truth;
  for (size_t i = 0; i < climbing.size(); ++i) climbing[i].translation().z() += 0.01 * kSpacing * static_cast<double>(i);
  const DriftError height = averageDrift(kittiSegmentErrors(ground_truth, climbing));
  EXPECT_NEAR(height.t_rel_percent, 1.0, 1e-4);
  EXPECT_NEAR(height.t_rel_horizontal_percent, 0.0, 1e-9);
  const DriftError along = averageDrift(kittiSegmentErrors(ground_truth, test::scaleIncrements(ground_truth, 1.01)));
  EXPECT_NEAR(along.t_rel_horizontal_percent, 1.0, 1e-6);
}

TEST(KittiMetric, ScaledIncrementsOnACircleGiveTheChordError) {
  // On a circle the segment's chord is shorter than its path, and the error is 1% of the chord:
  // 2 R sin(n turn / 2), with R the radius through frames `spacing` apart and n frames in the segment.
  const double spacing = 0.73;  // no segment length is a whole number of spacings
  const double turn = 0.002;
  const std::vector<Eigen::Isometry3d> ground_truth = test::circle(1400, spacing, turn);
  const std::vector<SegmentError> segments =
      kittiSegmentErrors(ground_truth, test::scaleIncrements(ground_truth, 1.01));
  const double radius = spacing / (2.0 * std::sin(turn / 2.0));
  for (const LengthDriftError& entry : driftByLength(segments)) {
    const double frames = std::floor(entry.length / spacing) + 1.0;
    const double chord = 2.0 * radius * std::sin(frames * turn / 2.0);
    EXPECT_NEAR(entry.error.t_rel_percent, chord / entry.length, 1e-9) << entry.length << " m";
    EXPECT_NEAR(entry.error.r_rel_deg_per_100m, 0.0, 1e-5);
  }
}

TEST(KittiMetric, ConstantYawRateErrorGivesItsRate) {
  const double yaw_error_per_frame = 1e-4;  // rad; frames are 1 m apart, so rad per metre
  const std::vector<Eigen::Isometry3d> ground_truth = test::straightLine(kFrames, kSpacing);
  std::vector<Eigen::Isometry3d> estimate;
  for (size_t i = 0; i < ground_truth.size(); ++i) {
    estimate.push_back(ground_truth[i] * test::yaw(yaw_error_per_frame * static_cast<double>(i)));
  }
  const DriftError drift = averageDrift(kittiSegmentErrors(ground_truth, estimate));
  const double expected_deg_per_100m = yaw_error_per_frame * 180.0 / M_PI * 100.0;
  EXPECT_NEAR(drift.r_rel_deg_per_100m, expected_deg_per_100m, 1e-9 * expected_deg_per_100m);
}

TEST(KittiMetric, RigidlyMovedEstimateHasNoDrift) {
  const std::vector<Eigen::Isometry3d> ground_truth = test::circle(kFrames, 1.1, 0.004);
  const Eigen::Isometry3d offset = test::translation(Eigen::Vector3d(5, -3, 2)) * test::yaw(1.2);
  std::vector<Eigen::Isometry3d> estimate;
  for (const Eigen::Isometry3d& pose : ground_truth) estimate.push_back(offset * pose);
  const DriftError drift = averageDrift(kittiSegmentErrors(ground_truth, estimate));
  EXPECT_NEAR(drift.t_rel_percent, 0.0, 1e-9);
  EXPECT_NEAR(drift.r_rel_deg_per_100m, 0.0, 1e-5);
}

TEST(KittiMetric, TrajectoryShorterThan100mHasNoSegments) {
  const std::vector<Eigen::Isometry3d> trajectory = test::straightLine(50, 1.0);
  const DriftError drift = averageDrift(kittiSegmentErrors(trajectory, trajectory));
  EXPECT_EQ(drift.segments, 0u);
  EXPECT_TRUE(std::isnan(drift.t_rel_percent));
  EXPECT_TRUE(driftByLength({}).empty());
}

TEST(KittiMetric, DifferentFrameCountsThrowNamingBoth) {
  try {
    kittiSegmentErrors(test::straightLine(12, 1.0), test::straightLine(11, 1.0));
    ADD_FAILURE() << "expected std::invalid_argument";
  } catch (const std::invalid_argument& error) {
    EXPECT_NE(std::string(error.what()).find("12 poses"), std::string::npos) << error.what();
    EXPECT_NE(std::string(error.what()).find("11"), std::string::npos) << error.what();
  }
}

}  // namespace
}  // namespace elo
