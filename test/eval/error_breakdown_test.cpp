#include "elo/eval/error_breakdown.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "synthetic_trajectories.hpp"

namespace elo {
namespace {

// Slightly over 1 m a frame, so that a segment of L metres ends exactly L frames after its start.
constexpr double kSpacing = 1.0 + 1e-9;
constexpr size_t kFrames = 300;
const std::vector<double> kLengths = {10, 20, 50, 100};
constexpr double kDegreesPer100mPerRadPerMetre = 100.0 * 180.0 / M_PI;

ErrorBreakdown breakdownOf(const std::vector<Eigen::Isometry3d>& ground_truth,
                           const std::vector<Eigen::Isometry3d>& estimate) {
  return averageBreakdown(
      segmentComponents(ground_truth, estimate, kittiSegmentErrors(ground_truth, estimate, kLengths)));
}

// Every component but those named is zero.
void expectOnly(const ErrorBreakdown& breakdown, const ErrorBreakdown& expected, double tolerance) {
  EXPECT_GT(breakdown.segments, 0u);
  EXPECT_NEAR(breakdown.heading_deg_per_100m, expected.heading_deg_per_100m, tolerance);
  EXPECT_NEAR(breakdown.pitch_deg_per_100m, expected.pitch_deg_per_100m, tolerance);
  EXPECT_NEAR(breakdown.roll_deg_per_100m, expected.roll_deg_per_100m, tolerance);
  EXPECT_NEAR(breakdown.along_track_percent, expected.along_track_percent, tolerance);
  EXPECT_NEAR(breakdown.cross_track_percent, expected.cross_track_percent, tolerance);
  EXPECT_NEAR(breakdown.height_percent, expected.height_percent, tolerance);
}

// One segment of `length` m from the identity, the truth ending at `truth` and the estimate at `estimate`.
ErrorBreakdown breakdownOfOneSegment(const Eigen::Isometry3d& truth, const Eigen::Isometry3d& estimate, double length) {
  const Eigen::Isometry3d start = Eigen::Isometry3d::Identity();
  return averageBreakdown(segmentComponents({start, truth}, {start, estimate}, {{0, 1, length}}));
}

// An estimate whose position i is the truth's moved by `offset_per_frame` * i in the vehicle's frame.
std::vector<Eigen::Isometry3d> movedBy(const std::vector<Eigen::Isometry3d>& ground_truth,
                                       const Eigen::Vector3d& offset_per_frame) {
  std::vector<Eigen::Isometry3d> estimate = ground_truth;
  for (size_t i = 0; i < estimate.size(); ++i) {
    estimate[i].translation() += ground_truth[i].linear() * (offset_per_frame * static_cast<double>(i));
  }
  return estimate;
}

TEST(ErrorBreakdown, GroundTruthAgainstItselfHasNoComponent) {
  const std::vector<Eigen::Isometry3d> drive = test::circle(kFrames, 1.3, 0.01);
  expectOnly(breakdownOf(drive, drive), {}, 1e-5);
}

// A scale error is along-track only, with its sign: 1% too far is +1%, 1% short is -1%.
TEST(ErrorBreakdown, ScaleErrorIsASignedAlongTrackFigureOnly) {
  const std::vector<Eigen::Isometry3d> straight = test::straightLine(kFrames, kSpacing);
  ErrorBreakdown too_far;
  too_far.along_track_percent = 1.0;
  expectOnly(breakdownOf(straight, test::scaleIncrements(straight, 1.01)), too_far, 1e-6);
  ErrorBreakdown too_short;
  too_short.along_track_percent = -1.0;
  expectOnly(breakdownOf(straight, test::scaleIncrements(straight, 0.99)), too_short, 1e-6);

  // On a bend a scale error lies along the chord, not along the vehicle's x: all of t_rel is along-track.
  const std::vector<Eigen::Isometry3d> bend = test::circle(kFrames, 0.73, 0.01);
  const std::vector<Eigen::Isometry3d> scaled = test::scaleIncrements(bend, 1.01);
  const ErrorBreakdown on_bend = breakdownOf(bend, scaled);
  EXPECT_NEAR(on_bend.along_track_percent, averageDrift(kittiSegmentErrors(bend, scaled, kLengths)).t_rel_percent, 1e-9);
  EXPECT_NEAR(on_bend.cross_track_percent, 0.0, 1e-9);
  EXPECT_NEAR(on_bend.height_percent, 0.0, 1e-9);
  EXPECT_NEAR(on_bend.heading_deg_per_100m, 0.0, 1e-5);
}

// A segment whose estimate ends turned about one of the vehicle's axes, in the right place, has that
// rotation in its own column only: heading, pitch or roll. Along a drive a heading error also moves the
// positions that follow (cross-track), so one segment shows it alone.
TEST(ErrorBreakdown, RotationErrorsGoToTheirOwnAxis) {
  const Eigen::Isometry3d truth = test::translation(Eigen::Vector3d(45, 12, 1.5)) * test::yaw(0.3);
  const double length = 50.0;
  const double angle = 0.01;  // rad
  const double expected = angle / length * kDegreesPer100mPerRadPerMetre;
  const auto turned = [&](const Eigen::Vector3d& axis) { return truth * Eigen::Isometry3d(Eigen::AngleAxisd(angle, axis)); };
  ErrorBreakdown heading;
  heading.heading_deg_per_100m = expected;
  expectOnly(breakdownOfOneSegment(truth, turned(Eigen::Vector3d::UnitZ()), length), heading, 1e-9);
  ErrorBreakdown pitch;
  pitch.pitch_deg_per_100m = expected;
  expectOnly(breakdownOfOneSegment(truth, turned(-Eigen::Vector3d::UnitY()), length), pitch, 1e-9);
  ErrorBreakdown roll;
  roll.roll_deg_per_100m = expected;
  expectOnly(breakdownOfOneSegment(truth, turned(Eigen::Vector3d::UnitX()), length), roll, 1e-9);
}

// A lateral drift of 1 cm a metre is 1% cross-track, to either side; a climb of 1 cm a metre is 1%
// height, on a road that heads north-east and climbs 3 deg, the vehicle facing along it.
TEST(ErrorBreakdown, LateralAndVerticalDriftsAreCrossTrackAndHeight) {
  const Eigen::Isometry3d heading(Eigen::AngleAxisd(0.7, Eigen::Vector3d::UnitZ()) *
                                  Eigen::AngleAxisd(-0.05, Eigen::Vector3d::UnitY()));
  std::vector<Eigen::Isometry3d> drive = test::chain(test::translation(Eigen::Vector3d(kSpacing, 0, 0)), kFrames);
  for (Eigen::Isometry3d& pose : drive) pose = heading * pose;
  ErrorBreakdown cross;
  cross.cross_track_percent = 1.0;
  expectOnly(breakdownOf(drive, movedBy(drive, Eigen::Vector3d(0, 0.01, 0))), cross, 1e-6);
  expectOnly(breakdownOf(drive, movedBy(drive, Eigen::Vector3d(0, -0.01, 0))), cross, 1e-6);
  ErrorBreakdown height;
  height.height_percent = 1.0;
  expectOnly(breakdownOf(drive, movedBy(drive, Eigen::Vector3d(0, 0, 0.01))), height, 1e-6);
}

TEST(ErrorBreakdown, NoSegmentsGiveNaN) {
  const ErrorBreakdown breakdown = averageBreakdown({});
  EXPECT_EQ(breakdown.segments, 0u);
  EXPECT_TRUE(std::isnan(breakdown.heading_deg_per_100m));
  EXPECT_TRUE(std::isnan(breakdown.along_track_percent));
}

}  // namespace
}  // namespace elo
