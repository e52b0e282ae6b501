// The elo_eval command line, run as a user runs it.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "../io/temp_directory.hpp"
#include "../io/test_helpers.hpp"
#include "../tools/run_command.hpp"
#include "elo/io/kitti.hpp"
#include "synthetic_trajectories.hpp"

namespace elo {
namespace {

using test::CommandResult;
using test::contains;

CommandResult runEloEval(const std::string& arguments) {
  return test::runCommand(std::string(ELO_EVAL_BINARY) + " " + arguments);
}

class EloEvalCli : public testing::Test {
 protected:
  void SetUp() override {
    ground_truth_ = test::circle(1200, 1.0, 0.003);
    std::filesystem::create_directories(directory_.path() / "gt");
    std::filesystem::create_directories(directory_.path() / "est");
    for (const char* sequence : {"00", "01"}) {
      writeKittiPoses(directory_.file(std::string("gt/") + sequence + ".txt"), ground_truth_);
      writeKittiPoses(directory_.file(std::string("est/") + sequence + ".txt"),
                      test::scaleIncrements(ground_truth_, 1.01));
    }
  }

  test::TempDirectory directory_;
  std::vector<Eigen::Isometry3d> ground_truth_;
};

TEST_F(EloEvalCli, HelpPrintsUsage) {
  const CommandResult result = runEloEval("--help");
  EXPECT_EQ(result.exit_code, 0);
  EXPECT_TRUE(contains(result.output, "usage: elo_eval --gt GT --est EST")) << result.output;
}

TEST_F(EloEvalCli, FilesGiveOneRow) {
  const CommandResult result = runEloEval("--gt " + directory_.file("gt/00.txt") + " --est " + directory_.file("est/00.txt"));
  EXPECT_EQ(result.exit_code, 0) << result.output;
  EXPECT_TRUE(contains(result.output, "t_rel(%)")) << result.output;
  EXPECT_TRUE(contains(result.output, "00 ")) << result.output;
  EXPECT_FALSE(contains(result.output, "overall")) << result.output;
}

TEST_F(EloEvalCli, DirectoriesGiveARowPerSequenceAndOverall) {
  const CommandResult result = runEloEval("--gt " + directory_.file("gt") + " --est " + directory_.file("est") +
                                          " --plot " + directory_.file("plot.png"));
  EXPECT_EQ(result.exit_code, 0) << result.output;
  std::istringstream lines(result.output);
  std::vector<std::string> rows;
  for (std::string line; std::getline(lines, line);) rows.push_back(line);
  ASSERT_EQ(rows.size(), 4u) << result.output;
  EXPECT_EQ(rows[1].substr(0, 2), "00");
  EXPECT_EQ(rows[2].substr(0, 2), "01");
  EXPECT_EQ(rows[3].substr(0, 7), "overall");
  EXPECT_TRUE(contains(rows[3], " 2400 ")) << rows[3];
  if (std::system("command -v gnuplot > /dev/null 2>&1") == 0) {
    EXPECT_TRUE(std::filesystem::exists(directory_.file("plot_00.png")));
    EXPECT_TRUE(std::filesystem::exists(directory_.file("plot_01.png")));
    EXPECT_TRUE(std::filesystem::exists(directory_.file("plot.png")));
  }
}

// The whitespace-separated fields of the output's first line that starts with `start`.
std::vector<std::string> fieldsOfRow(const std::string& output, const std::string& start) {
  std::istringstream lines(output);
  for (std::string line; std::getline(lines, line);) {
    if (line.rfind(start, 0) != 0) continue;
    std::istringstream words(line);
    std::vector<std::string> fields;
    for (std::string word; words >> word;) fields.push_back(word);
    return fields;
  }
  return {};
}

// The estimate is 1% too long on every segment: the breakdown puts it all along the track, signed.
TEST_F(EloEvalCli, SegmentsAndBreakdown) {
  const CommandResult result = runEloEval("--gt " + directory_.file("gt/00.txt") + " --est " +
                                          directory_.file("est/00.txt") + " --segments 10,50 --breakdown");
  EXPECT_EQ(result.exit_code, 0) << result.output;
  ASSERT_TRUE(contains(result.output, "heading(deg/100m)")) << result.output;
  const std::vector<std::string> drift = fieldsOfRow(result.output, "00 ");
  ASSERT_EQ(drift.size(), 9u) << result.output;
  // Over 1%: a segment ends at the first frame beyond its length, 11 m after its start for 10 m.
  EXPECT_NEAR(std::stod(drift[3]), 1.05, 0.05) << "t_rel over 10 and 50 m on a gentle curve";
  std::istringstream after_header(result.output.substr(result.output.find("heading(deg/100m)")));
  std::string header;
  std::getline(after_header, header);
  std::string row;
  std::getline(after_header, row);
  const std::vector<std::string> breakdown = fieldsOfRow(row, "00 ");
  ASSERT_EQ(breakdown.size(), 7u) << result.output;
  EXPECT_EQ(breakdown[4][0], '+') << "along-track, too far: " << row;
  EXPECT_NEAR(std::stod(breakdown[4]), std::stod(drift[3]), 1e-3) << row;
  EXPECT_NEAR(std::stod(breakdown[1]), 0.0, 1e-3) << "heading: " << row;
  EXPECT_NEAR(std::stod(breakdown[5]), 0.0, 1e-3) << "cross-track: " << row;
  EXPECT_EQ(runEloEval("--gt " + directory_.file("gt/00.txt") + " --est " + directory_.file("est/00.txt") +
                       " --segments 10,x").exit_code, 2);
  EXPECT_EQ(runEloEval("--gt " + directory_.file("gt/00.txt") + " --est " + directory_.file("est/00.txt") +
                       " --segments 0").exit_code, 2);
  EXPECT_EQ(runEloEval("--est " + directory_.file("est/00.txt") + " --breakdown").exit_code, 2);
}

// A run started at scan 100 (elo_run --start 100) whose pose 10 is 0.3 m ahead of where it should be:
// scored against the ground truth from pose 100 on.
TEST_F(EloEvalCli, StartAndPoseErrorsScoreARunStartedMidDrive) {
  std::vector<Eigen::Isometry3d> run;
  for (size_t i = 100; i < 120; ++i) run.push_back(ground_truth_[100].inverse() * ground_truth_[i]);
  run[10].translation() += run[10].linear() * Eigen::Vector3d(0.3, 0, 0);
  writeKittiPoses(directory_.file("run.txt"), run);
  const std::string files = "--gt " + directory_.file("gt/00.txt") + " --est " + directory_.file("run.txt");
  const CommandResult result = runEloEval(files + " --start 100 --pose-errors 1,10");
  EXPECT_EQ(result.exit_code, 0) << result.output;
  EXPECT_TRUE(contains(result.output, "translation(m)")) << result.output;
  EXPECT_TRUE(contains(result.output, "run             1          0.0000")) << result.output;
  EXPECT_TRUE(contains(result.output, "run            10          0.3000")) << result.output;
  EXPECT_EQ(runEloEval(files).exit_code, 2) << "20 poses against 1200 without --start";
  const CommandResult beyond = runEloEval(files + " --start 1190");
  EXPECT_EQ(beyond.exit_code, 2);
  EXPECT_TRUE(contains(beyond.output, "too few for 20 estimated poses from pose 1190 on")) << beyond.output;
  EXPECT_EQ(runEloEval(files + " --start 100 --pose-errors 20").exit_code, 2);
  // --start 0: a run of the drive's first scans, scored against as many ground-truth poses.
  std::vector<Eigen::Isometry3d> first_scans(ground_truth_.begin(), ground_truth_.begin() + 20);
  writeKittiPoses(directory_.file("first.txt"), first_scans);
  const CommandResult from_zero = runEloEval("--gt " + directory_.file("gt/00.txt") + " --est " +
                                             directory_.file("first.txt") + " --start 0 --pose-errors 10");
  EXPECT_EQ(from_zero.exit_code, 0) << from_zero.output;
  EXPECT_TRUE(contains(from_zero.output, "first          10          0.0000")) << from_zero.output;
}

// KITTI-raw's stamps: a sensor scanning every 0.1035 s, each scan stamped with the 10 ms OXTS sample
// nearest. The estimate is exact at the scans' instants; the ground truth, at 20 m/s, is taken at the
// stamps, up to 0.1 m off. --gt-times scores against the ground truth moved to the instants.
TEST_F(EloEvalCli, GroundTruthTimesMoveItToTheScansInstants) {
  std::vector<Eigen::Isometry3d> truth_at_stamps;
  std::vector<Eigen::Isometry3d> exact;
  std::string stamps;
  for (int i = 0; i < 40; ++i) {
    const double instant = 0.0031 + 0.1035 * i;
    const double stamp = std::round(instant * 100.0) / 100.0;
    stamps += std::to_string(stamp) + "\n";
    truth_at_stamps.push_back(test::translation(Eigen::Vector3d(20.0 * stamp, 0, 0)));
    exact.push_back(test::translation(Eigen::Vector3d(20.0 * instant, 0, 0)));
  }
  writeKittiPoses(directory_.file("truth.txt"), truth_at_stamps);
  writeKittiPoses(directory_.file("exact.txt"), exact);
  test::writeText(directory_.file("times.txt"), stamps);
  const std::string files = "--gt " + directory_.file("truth.txt") + " --est " + directory_.file("exact.txt");
  // Pose 1's translation error, from the --pose-errors table.
  const auto pose_1_error = [](const std::string& output) {
    return std::stod(fieldsOfRow(output.substr(output.find("translation(m)")), "exact ").at(2));
  };
  const double at_stamps = pose_1_error(runEloEval(files + " --pose-errors 1").output);
  EXPECT_NEAR(at_stamps, 20.0 * (0.11 - 0.1035), 1e-4) << "scan 1 stamped 0.11 s, 6.5 ms late";
  const CommandResult moved = runEloEval(files + " --gt-times " + directory_.file("times.txt") + " --pose-errors 1");
  EXPECT_EQ(moved.exit_code, 0) << moved.output;
  EXPECT_TRUE(contains(moved.output, "interpolated to uniform instants")) << moved.output;
  EXPECT_LT(pose_1_error(moved.output), 0.002) << moved.output;

  test::writeText(directory_.file("short_times.txt"), "0.0\n0.1\n");
  const CommandResult too_few = runEloEval(files + " --gt-times " + directory_.file("short_times.txt"));
  EXPECT_EQ(too_few.exit_code, 2);
  EXPECT_TRUE(contains(too_few.output, "40 poses for 2 stamps")) << too_few.output;
  EXPECT_EQ(runEloEval(files + " --gt-times /nonexistent/times.txt").exit_code, 2);
  EXPECT_EQ(runEloEval(files + " --tum --gt-times " + directory_.file("times.txt")).exit_code, 2);
}

// A ground truth that strays 0.5 m sideways over frames 600-649 of the circle: --exclude-frames leaves the
// segments holding them out, in the ground truth's frames with --start too.
TEST_F(EloEvalCli, ExcludedFramesLeaveTheirSegmentsOut) {
  std::vector<Eigen::Isometry3d> straying = ground_truth_;
  for (size_t i = 600; i < 650; ++i) straying[i].translation().y() += 0.5;
  writeKittiPoses(directory_.file("straying.txt"), straying);
  writeKittiPoses(directory_.file("exact.txt"), ground_truth_);
  const std::string files = "--gt " + directory_.file("straying.txt") + " --est " + directory_.file("exact.txt") +
                            " --segments 10,50 --segment-step 1";
  const auto t_rel = [](const std::string& output) { return std::stod(fieldsOfRow(output, "exact ").at(3)); };
  const CommandResult all = runEloEval(files);
  EXPECT_EQ(all.exit_code, 0) << all.output;
  EXPECT_GT(t_rel(all.output), 0.05) << all.output;
  const CommandResult clear = runEloEval(files + " --exclude-frames 600-649");
  EXPECT_EQ(clear.exit_code, 0) << clear.output;
  EXPECT_NEAR(t_rel(clear.output), 0.0, 1e-6) << clear.output;
  EXPECT_TRUE(contains(clear.output, "segments hold an excluded frame and are left out")) << clear.output;
  // Single frames and ranges together: 600-649 given as 600,601-649.
  EXPECT_NEAR(t_rel(runEloEval(files + " --exclude-frames 600,601-649").output), 0.0, 1e-6);
  // Frames 500-899 scored from ground-truth frame 500 on: the stray is still at the ground truth's 600-649.
  writeKittiPoses(directory_.file("from_500.txt"),
                  std::vector<Eigen::Isometry3d>(ground_truth_.begin() + 500, ground_truth_.begin() + 900));
  const std::string from_500 = "--gt " + directory_.file("straying.txt") + " --est " + directory_.file("from_500.txt") +
                               " --segments 10,50 --segment-step 1 --start 500";
  const auto t_rel_from_500 = [](const std::string& output) {
    return std::stod(fieldsOfRow(output, "from_500 ").at(3));
  };
  EXPECT_GT(t_rel_from_500(runEloEval(from_500).output), 0.05);
  EXPECT_NEAR(t_rel_from_500(runEloEval(from_500 + " --exclude-frames 600-649").output), 0.0, 1e-6);
  EXPECT_GT(t_rel_from_500(runEloEval(from_500 + " --exclude-frames 100-149").output), 0.05);
  for (const char* bad : {"649-600", "x", "600-", "-5", ""}) {
    EXPECT_EQ(runEloEval(files + " --exclude-frames '" + bad + "'").exit_code, 2) << bad;
  }
  const CommandResult beyond = runEloEval(files + " --exclude-frames 600-649,1190-1200");
  EXPECT_EQ(beyond.exit_code, 2);
  EXPECT_TRUE(contains(beyond.output, "--exclude-frames 1190-1200: ")) << beyond.output;
  EXPECT_TRUE(contains(beyond.output, "has 1200 poses")) << beyond.output;
  EXPECT_EQ(runEloEval("--gt " + directory_.file("gt") + " --est " + directory_.file("est") + " --exclude-frames 1-2")
                .exit_code,
            2)
      << "directories";
}

TEST_F(EloEvalCli, TumFiles) {
  std::vector<double> stamps;
  for (size_t i = 0; i < ground_truth_.size(); ++i) stamps.push_back(0.1 * static_cast<double>(i));
  writeTumPoses(directory_.file("gt.tum"), stamps, ground_truth_);
  writeTumPoses(directory_.file("est.tum"), stamps, ground_truth_);
  const CommandResult result =
      runEloEval("--tum --gt " + directory_.file("gt.tum") + " --est " + directory_.file("est.tum"));
  EXPECT_EQ(result.exit_code, 0) << result.output;
  EXPECT_TRUE(contains(result.output, "0.0000")) << result.output;
}

TEST_F(EloEvalCli, MismatchedFrameCountsNameBoth) {
  writeKittiPoses(directory_.file("short.txt"), test::circle(1000, 1.0, 0.003));
  const CommandResult result =
      runEloEval("--gt " + directory_.file("gt/00.txt") + " --est " + directory_.file("short.txt"));
  EXPECT_EQ(result.exit_code, 2);
  EXPECT_TRUE(contains(result.output, "1200")) << result.output;
  EXPECT_TRUE(contains(result.output, "1000")) << result.output;
}

TEST_F(EloEvalCli, BadArgumentsExitWith2) {
  EXPECT_EQ(runEloEval("").exit_code, 2);
  EXPECT_EQ(runEloEval("--gt " + directory_.file("gt/00.txt")).exit_code, 2);
  EXPECT_EQ(runEloEval("--gt " + directory_.file("gt/00.txt") + " --est").exit_code, 2);
  EXPECT_EQ(runEloEval("--bogus").exit_code, 2);
  EXPECT_EQ(runEloEval("--gt " + directory_.file("gt") + " --est " + directory_.file("est/00.txt")).exit_code, 2);
}

TEST_F(EloEvalCli, UnreadableFilesExitWith2NamingThem) {
  const CommandResult missing = runEloEval("--gt /nonexistent/00.txt --est " + directory_.file("est/00.txt"));
  EXPECT_EQ(missing.exit_code, 2);
  EXPECT_TRUE(contains(missing.output, "/nonexistent/00.txt")) << missing.output;

  test::writeText(directory_.file("broken.txt"), "1 2 3\n");
  const CommandResult broken = runEloEval("--gt " + directory_.file("gt/00.txt") + " --est " + directory_.file("broken.txt"));
  EXPECT_EQ(broken.exit_code, 2);
  EXPECT_TRUE(contains(broken.output, directory_.file("broken.txt") + ":1")) << broken.output;
}

// Two scans of a wall 10 m ahead from the same place, in a flat sequence directory. Its points alternate
// 5 mm in front of and behind the plane x = 10, so that it has a thickness to measure.
std::string writeWallScans(const test::TempDirectory& directory) {
  std::filesystem::create_directories(directory.path() / "scans");
  PointCloud wall;
  for (int i = 0; i < 300; ++i) {
    for (int j = 0; j < 100; ++j) wall.points.emplace_back((i + j) % 2 ? 10.005f : 9.995f, -3.0f + 0.02f * i, -1.0f + 0.02f * j);
  }
  for (const char* name : {"000000.bin", "000001.bin"}) writeKittiBin(directory.file(std::string("scans/") + name), wall);
  return directory.file("scans");
}

TEST_F(EloEvalCli, MapEntropyScoresATrajectoryWithoutGroundTruth) {
  const std::string scans = writeWallScans(directory_);
  writeKittiPoses(directory_.file("still.txt"), {Eigen::Isometry3d::Identity(), Eigen::Isometry3d::Identity()});
  const CommandResult result = runEloEval("--est " + directory_.file("still.txt") + " --map-entropy " + scans);
  EXPECT_EQ(result.exit_code, 0) << result.output;
  EXPECT_TRUE(contains(result.output, "map entropy")) << result.output;
  EXPECT_TRUE(contains(result.output, "plane deviation 5.0")) << result.output;
}

TEST_F(EloEvalCli, MapEntropyNeedsOnePosePerScan) {
  const std::string scans = writeWallScans(directory_);
  writeKittiPoses(directory_.file("three.txt"), std::vector<Eigen::Isometry3d>(3, Eigen::Isometry3d::Identity()));
  const CommandResult result = runEloEval("--est " + directory_.file("three.txt") + " --map-entropy " + scans);
  EXPECT_EQ(result.exit_code, 2);
  EXPECT_TRUE(contains(result.output, "3 poses for the 2 scans")) << result.output;
  EXPECT_EQ(runEloEval("--est " + directory_.file("est") + " --map-entropy " + scans).exit_code, 2);
}

TEST_F(EloEvalCli, ReverseReportsHowFarAForwardAndAReverseRunFailToClose) {
  // 10 m straight ahead; the reverse run comes back 10.05 m.
  writeKittiPoses(directory_.file("forward.txt"), test::circle(11, 1.0, 0.0));
  writeKittiPoses(directory_.file("reverse.txt"), test::circle(11, -1.005, 0.0));
  const CommandResult result =
      runEloEval("--est " + directory_.file("forward.txt") + " --reverse " + directory_.file("reverse.txt"));
  EXPECT_EQ(result.exit_code, 0) << result.output;
  EXPECT_TRUE(contains(result.output, "forward-backward gap 0.0500 m, 0.0000 deg over 11 scans and 10.0 m (0.500 %"))
      << result.output;
}

TEST_F(EloEvalCli, ReverseNeedsARunOverTheSameScans) {
  writeKittiPoses(directory_.file("forward.txt"), test::circle(11, 1.0, 0.0));
  writeKittiPoses(directory_.file("short.txt"), test::circle(10, -1.0, 0.0));
  const CommandResult result =
      runEloEval("--est " + directory_.file("forward.txt") + " --reverse " + directory_.file("short.txt"));
  EXPECT_EQ(result.exit_code, 2);
  EXPECT_TRUE(contains(result.output, "the forward run has 11 poses and the reverse run 10")) << result.output;
  EXPECT_EQ(runEloEval("--est " + directory_.file("est") + " --reverse " + directory_.file("short.txt")).exit_code, 2);
}

}  // namespace
}  // namespace elo
