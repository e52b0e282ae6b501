#include "elo/eval/plot.hpp"

#include <gtest/gtest.h>
#include <stdlib.h>

#include <cstdlib>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <utility>

#include "../io/temp_directory.hpp"
#include "synthetic_trajectories.hpp"

namespace elo {
namespace {

bool gnuplotInstalled() { return std::system("command -v gnuplot > /dev/null 2>&1") == 0; }

bool isPng(const std::string& path) {
  std::ifstream stream(path, std::ios::binary);
  char signature[8] = {};
  stream.read(signature, sizeof(signature));
  return stream && std::string(signature + 1, 3) == "PNG";
}

// Sets an environment variable for one scope.
class ScopedEnvironment {
 public:
  ScopedEnvironment(const char* name, const std::string& value) : name_(name) {
    if (const char* old = std::getenv(name)) old_value_ = old;
    setenv(name, value.c_str(), 1);
  }
  ~ScopedEnvironment() { setenv(name_, old_value_.c_str(), 1); }

 private:
  const char* name_;
  std::string old_value_;
};

TEST(Plot, WritesAPngOfTrajectoryAndDrift) {
  if (!gnuplotInstalled()) GTEST_SKIP() << "gnuplot is not installed";
  test::TempDirectory directory;
  const std::vector<Eigen::Isometry3d> ground_truth = test::circle(1200, 1.0, 0.004);
  const std::vector<Eigen::Isometry3d> estimate = test::scaleIncrements(ground_truth, 1.02);
  const std::string png = directory.file("it's a plot.png");  // a quote survives shell and gnuplot quoting
  EXPECT_TRUE(plotEvaluation(png, ground_truth, estimate, driftByLength(kittiSegmentErrors(ground_truth, estimate)),
                             TopView::lidar_xy, "circle"));
  EXPECT_TRUE(isPng(png));
}

TEST(Plot, DriftOnlyWithoutTrajectories) {
  if (!gnuplotInstalled()) GTEST_SKIP() << "gnuplot is not installed";
  test::TempDirectory directory;
  const std::vector<Eigen::Isometry3d> ground_truth = test::circle(1200, 1.0, 0.004);
  const std::vector<LengthDriftError> drift =
      driftByLength(kittiSegmentErrors(ground_truth, test::scaleIncrements(ground_truth, 1.02)));
  EXPECT_TRUE(plotEvaluation(directory.file("drift.png"), {}, {}, drift));
  EXPECT_TRUE(isPng(directory.file("drift.png")));
}

TEST(Plot, ShortTrajectoryPlotsWithoutDriftPanels) {
  if (!gnuplotInstalled()) GTEST_SKIP() << "gnuplot is not installed";
  test::TempDirectory directory;
  const std::vector<Eigen::Isometry3d> trajectory = test::circle(30, 1.0, 0.05);
  EXPECT_TRUE(plotEvaluation(directory.file("short.png"), trajectory, trajectory, {}, TopView::widest_spread));
  EXPECT_TRUE(isPng(directory.file("short.png")));
}

// The width and height of a PNG, from its IHDR chunk.
std::pair<uint32_t, uint32_t> pngSize(const std::string& path) {
  std::ifstream stream(path, std::ios::binary);
  unsigned char header[24] = {};
  stream.read(reinterpret_cast<char*>(header), sizeof(header));
  const auto bigEndian = [&](int offset) {
    return uint32_t{header[offset]} << 24 | uint32_t{header[offset + 1]} << 16 | uint32_t{header[offset + 2]} << 8 |
           uint32_t{header[offset + 3]};
  };
  return {bigEndian(16), bigEndian(20)};
}

// A kilometre of straight road, drifting sideways by 2 m: equal scale alone would draw a strip 1:500.
TEST(Plot, LongStraightDriveGetsATopViewOfReadableHeight) {
  const std::vector<Eigen::Isometry3d> ground_truth = test::circle(1001, 1.0, 0.0);  // along x
  std::vector<Eigen::Isometry3d> estimate = ground_truth;
  for (size_t i = 0; i < estimate.size(); ++i) estimate[i].translation().y() += 0.002 * static_cast<double>(i);
  const TopViewFrame frame = topViewFrame(ground_truth, estimate, TopView::lidar_xy);
  EXPECT_EQ(frame.axes, std::make_pair(0, 1));
  const Eigen::Vector2d span = frame.high - frame.low;
  EXPECT_GT(span.x(), 1000.0);
  EXPECT_LT(span.x(), 1100.0);
  EXPECT_GE(span.y(), 0.3 * 1000.0) << "the narrow side is widened to at least 0.3 of the long one";
  for (const std::vector<Eigen::Isometry3d>* poses : {&ground_truth, &std::as_const(estimate)}) {
    for (const Eigen::Isometry3d& pose : *poses) {
      EXPECT_GE(pose.translation().x(), frame.low.x());
      EXPECT_LE(pose.translation().x(), frame.high.x());
      EXPECT_GE(pose.translation().y(), frame.low.y());
      EXPECT_LE(pose.translation().y(), frame.high.y());
    }
  }
  // At one scale across the 1280-pixel canvas, 0.3 of the length is well over 300 pixels high.
  EXPECT_GE(frame.height_px, 400);
  EXPECT_LE(frame.height_px, 900);

  if (!gnuplotInstalled()) GTEST_SKIP() << "gnuplot is not installed";
  test::TempDirectory directory;
  const std::string png = directory.file("straight.png");
  ASSERT_TRUE(plotEvaluation(png, ground_truth, estimate, driftByLength(kittiSegmentErrors(ground_truth, estimate)),
                             TopView::lidar_xy));
  const auto [width, height] = pngSize(png);
  EXPECT_EQ(width, 1280u);
  EXPECT_EQ(height, 30u + frame.height_px + 480u) << "title, top view, error panels";
}

// A drive as wide as long keeps its proportions and gets the tallest panel.
TEST(Plot, SquareDriveUsesTheTallestTopView) {
  const std::vector<Eigen::Isometry3d> ground_truth = test::circle(1200, 1.0, 2.0 * M_PI / 1200);
  const TopViewFrame frame = topViewFrame(ground_truth, ground_truth, TopView::lidar_xy);
  const Eigen::Vector2d span = frame.high - frame.low;
  EXPECT_NEAR(span.y() / span.x(), 1.0, 0.15) << "the key's room above the circle is all that differs";
  EXPECT_EQ(frame.height_px, 900);
}

TEST(Plot, MissingGnuplotWarnsAndReturnsFalse) {
  test::TempDirectory directory;
  const ScopedEnvironment no_programs("PATH", directory.path().string());
  const std::vector<Eigen::Isometry3d> trajectory = test::circle(30, 1.0, 0.05);
  testing::internal::CaptureStderr();
  EXPECT_FALSE(plotEvaluation(directory.file("none.png"), trajectory, trajectory, {}));
  const std::string warning = testing::internal::GetCapturedStderr();
  EXPECT_NE(warning.find("gnuplot is not installed"), std::string::npos) << warning;
  EXPECT_FALSE(std::filesystem::exists(directory.file("none.png")));
}

TEST(Plot, UnwritablePathReturnsFalse) {
  if (!gnuplotInstalled()) GTEST_SKIP() << "gnuplot is not installed";
  const std::vector<Eigen::Isometry3d> trajectory = test::circle(30, 1.0, 0.05);
  EXPECT_FALSE(plotEvaluation("/nonexistent/dir/plot.png", trajectory, trajectory, {}));
}

}  // namespace
}  // namespace elo
