#include "elo/eval/plot.hpp"

#include <gtest/gtest.h>
#include <stdlib.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>

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
