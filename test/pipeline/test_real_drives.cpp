// The real KITTI-raw drives with ground truth (docs/real_drives.md), the project's yardstick: ELO with
// config/kitti.yaml over each drive stays within a little of today's drift over 10-100 m segments, and a
// run started on a moving car is close to the truth from its first scans. The drives are not in the
// repository (KITTI is CC BY-NC-SA): they are read from $ELO_REAL_DRIVES, else from the CMake cache path
// ELO_REAL_DRIVES (default ../real_drives beside the source), and each test skips, saying where it
// looked, when its drive is absent.
#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <algorithm>
#include <map>
#include <stdexcept>
#include <string>
#include <vector>

#include "elo/eval/kitti_metric.hpp"
#include "elo/eval/trajectory_error.hpp"
#include "elo/eval/uniform_instants.hpp"
#include "elo/io/config_yaml.hpp"
#include "elo/io/kitti.hpp"
#include "elo/io/sequence.hpp"
#include "elo/pipeline/odometry.hpp"

namespace elo {
namespace {

const std::vector<double> kSegmentLengths = {10, 20, 50, 100};
constexpr size_t kSegmentStep = 1;  // a segment starting at every scan: the drives are 77-188 scans long

std::string drivesDirectory() {
  const char* from_environment = std::getenv("ELO_REAL_DRIVES");
  return from_environment != nullptr ? from_environment : ELO_REAL_DRIVES;
}

std::string drivePath(const std::string& drive) { return drivesDirectory() + "/" + drive; }

bool driveIsPresent(const std::string& drive) {
  return std::filesystem::is_directory(drivePath(drive) + "/velodyne") &&
         std::filesystem::is_regular_file(drivePath(drive) + "/poses.txt");
}

std::string absentMessage(const std::string& drive) {
  return "real drive " + drive + " not found under " + drivesDirectory() +
         " (set ELO_REAL_DRIVES; how to get the drives: docs/real_drives.md)";
}

// ELO as elo_run --config config/kitti.yaml --threads 2 runs it, over `frames` scans from `start` (all
// from there with 0), the first at the origin.
std::vector<Eigen::Isometry3d> runDrive(const Sequence& sequence, size_t start, size_t frames) {
  Config config;
  loadConfigYaml(std::string(ELO_SOURCE_DIR) + "/config/kitti.yaml", config);
  config.runtime.threads = 2;
  Odometry odometry(config);
  const size_t end = frames == 0 ? sequence.size() : std::min(sequence.size(), start + frames);
  std::vector<Eigen::Isometry3d> poses;
  for (size_t scan = start; scan < end; ++scan) {
    const FrameResult result = odometry.process(sequence.load(scan));
    EXPECT_TRUE(result.processed) << "scan " << scan << ": " << result.skip_reason;
    poses.push_back(result.pose);
  }
  return poses;
}

// A run over the drive and its ground truth from the run's first scan, as many poses as the run has: at
// the truth's stamps, and interpolated to the scans' uniform instants (docs/real_drives.md: the stamps
// are OXTS's, rounded to 10 ms, up to 0.1 m of travel off the scans').
struct DriveRun {
  std::vector<Eigen::Isometry3d> ground_truth;
  std::vector<Eigen::Isometry3d> truth_at_instants;
  std::vector<Eigen::Isometry3d> estimate;
};

std::vector<Eigen::Isometry3d> truthAtInstants(const std::string& drive, const std::vector<Eigen::Isometry3d>& truth) {
  const std::vector<double> stamps = readTimes(drivePath(drive) + "/times.txt");
  return interpolatePoses(truth, stamps, fitUniformInstants(stamps).instants);
}

DriveRun runOf(const std::string& drive, size_t start, size_t frames) {
  const Sequence sequence(drivePath(drive));
  DriveRun run;
  run.estimate = runDrive(sequence, start, frames);
  const auto from_start = [&](const std::vector<Eigen::Isometry3d>& truth) {
    return std::vector<Eigen::Isometry3d>(truth.begin() + static_cast<std::ptrdiff_t>(start),
                                          truth.begin() + static_cast<std::ptrdiff_t>(start + run.estimate.size()));
  };
  run.ground_truth = from_start(sequence.groundTruth());
  run.truth_at_instants = from_start(truthAtInstants(drive, sequence.groundTruth()));
  return run;
}

// The whole runs made so far in this process, by drive: each drive is run whole once per test binary.
std::map<std::string, DriveRun>& wholeRuns() {
  static std::map<std::string, DriveRun> runs;
  return runs;
}

const DriveRun& wholeDrive(const std::string& drive) {
  const auto found = wholeRuns().find(drive);
  if (found != wholeRuns().end()) return found->second;
  return wholeRuns().emplace(drive, runOf(drive, 0, 0)).first->second;
}

// `frames` scans from `start`: from the whole run when it started there and was made already (the
// odometry is causal, so its first poses are those of a shorter run), else a run of their own (ctest runs
// each test in a process of its own).
DriveRun firstScans(const std::string& drive, size_t start, size_t frames) {
  const auto whole = wholeRuns().find(drive);
  if (start != 0 || whole == wholeRuns().end()) return runOf(drive, start, frames);
  DriveRun run = whole->second;
  run.ground_truth.resize(std::min(frames, run.ground_truth.size()));
  run.truth_at_instants.resize(run.ground_truth.size());
  run.estimate.resize(run.ground_truth.size());
  return run;
}

// Today's figures (config/kitti.yaml, frame-to-model, segments of 10-100 m starting at every scan);
// the gate lets them grow by 15 % before it fails.
struct DriftCase {
  const char* drive;
  double t_rel_percent;
  double r_rel_deg_per_100m;
};
constexpr double kHeadroom = 1.15;

void PrintTo(const DriftCase& today, std::ostream* out) { *out << "drive " << today.drive; }

class RealDriveDrift : public testing::TestWithParam<DriftCase> {};

TEST_P(RealDriveDrift, StaysWithinTodaysFigures) {
  const DriftCase& today = GetParam();
  if (!driveIsPresent(today.drive)) GTEST_SKIP() << absentMessage(today.drive);
  // The name in a variable, not a temporary: GCC 14's -Wdangling-reference takes the reference returned
  // (into wholeRuns()) for one into the temporary string.
  const std::string drive = today.drive;
  const DriveRun& run = wholeDrive(drive);
  const DriftError drift = averageDrift(kittiSegmentErrors(run.ground_truth, run.estimate, kSegmentLengths, kSegmentStep));
  std::cout << "drive " << today.drive << ": t_rel " << drift.t_rel_percent << " %, r_rel "
            << drift.r_rel_deg_per_100m << " deg/100m over " << drift.segments << " segments" << std::endl;
  EXPECT_LT(drift.t_rel_percent, kHeadroom * today.t_rel_percent);
  EXPECT_LT(drift.r_rel_deg_per_100m, kHeadroom * today.r_rel_deg_per_100m);
}

INSTANTIATE_TEST_SUITE_P(Drives, RealDriveDrift,
                         testing::Values(DriftCase{"0001", 0.429, 0.346}, DriftCase{"0002", 0.561, 0.592},
                                         DriftCase{"0005", 5.098, 1.406}, DriftCase{"0027", 1.383, 0.226}),
                         [](const auto& info) { return std::string("drive_") + info.param.drive; });

// The scans of a drive where the ground truth's direction of travel strays from what OXTS's own speed and
// yaw rate give (tools/oxts_consistency.py --strays); none where it holds together.
std::vector<FrameRange> strayingScans(const std::string& drive) {
  const std::string command = "/usr/bin/python3 " + std::string(ELO_SOURCE_DIR) +
                              "/tools/oxts_consistency.py --strays " + drivePath(drive) + " 2>&1";
  FILE* pipe = popen(command.c_str(), "r");
  if (pipe == nullptr) throw std::runtime_error("cannot run " + command);
  std::string output;
  for (char buffer[256]; std::fgets(buffer, sizeof buffer, pipe) != nullptr;) output += buffer;
  if (pclose(pipe) != 0) throw std::runtime_error(command + " failed: " + output);
  const std::string ranges = output.substr(0, output.find('\n'));
  return ranges.empty() ? std::vector<FrameRange>{} : parseFrameRanges(ranges);
}

// 0005's ground truth strays over more than half of its scans (docs/real_drives.md): over the segments
// clear of them ELO stays within a little of today's figures there, which meet issue 43's targets
// against KISS-ICP's better figures over the same segments (t_rel no higher than its 3.32 %, r_rel at
// most half of its 1.80 deg/100 m, both with its deskew).
TEST(RealDriveClearSegments, Drive0005StaysWithinTodaysFiguresWhereItsTruthHoldsTogether) {
  const std::string drive = "0005";
  if (!driveIsPresent(drive)) GTEST_SKIP() << absentMessage(drive);
  const std::vector<FrameRange> strays = strayingScans(drive);
  ASSERT_FALSE(strays.empty()) << "0005's ground truth strays over scans 0-30, 32-42 and 48-88";
  const DriveRun& run = wholeDrive(drive);
  const std::vector<SegmentError> segments =
      kittiSegmentErrors(run.ground_truth, run.estimate, kSegmentLengths, kSegmentStep);
  const DriftError drift = averageDrift(segmentsClearOf(segments, strays));
  std::cout << "drive 0005, segments clear of the truth's strays: t_rel " << drift.t_rel_percent << " %, r_rel "
            << drift.r_rel_deg_per_100m << " deg/100m over " << drift.segments << " of " << segments.size()
            << " segments" << std::endl;
  EXPECT_GE(drift.segments, 60u);
  EXPECT_LT(drift.t_rel_percent, kHeadroom * 3.260);
  EXPECT_LT(drift.r_rel_deg_per_100m, kHeadroom * 0.867);
}

// A run started on a moving car: ELO at its first scan knows nothing of the motion, yet its 2nd scan
// must be within 0.10 m of the truth (relative to the 1st), the start search's doing
// (docs/start_in_motion.md), and its 11th within 0.30 m (issue 43's targets) or, where the run from the
// drive's first scan itself strays further over the same ten scans, within 0.05 m of that run: OXTS's
// direction of travel wanders off the odometry's, by 0.2-0.3 m sideways over ten scans of 0027 and 0.4 m
// over 0005's scans 60-70, whenever the odometry started. Its 11th scan's rotation must be within 0.1 deg
// of that run's: a start that kept the first scans' bent registration turned 0.2 deg more than tracking
// does over the same scans. The truth is taken at the scans' instants: at its stamps, 0.1 m at 20 m/s
// apart from them, the 2nd scan of 0027 from scan 177 is 0.13 m off where it is 0.02 m off the truth at
// its instant.
struct StartCase {
  const char* drive;
  size_t start;
};
constexpr size_t kStartFrames = 11;

void PrintTo(const StartCase& start, std::ostream* out) { *out << "drive " << start.drive << " from scan " << start.start; }

// The error after `scans` scans from scan `first` of the run from the drive's first scan: what tracking
// alone gives over the scans a start from `first` is scored on.
PoseError trackedError(const std::string& drive, size_t first, size_t scans) {
  const DriveRun& whole = wholeDrive(drive);
  const auto window = [first, scans](const std::vector<Eigen::Isometry3d>& poses) {
    return std::vector<Eigen::Isometry3d>(poses.begin() + static_cast<std::ptrdiff_t>(first),
                                          poses.begin() + static_cast<std::ptrdiff_t>(first + scans + 1));
  };
  return poseErrorFromFirst(window(whole.truth_at_instants), window(whole.estimate), scans);
}

class StartInMotion : public testing::TestWithParam<StartCase> {};

TEST_P(StartInMotion, FirstScansFollowTheTruth) {
  const StartCase& start = GetParam();
  if (!driveIsPresent(start.drive)) GTEST_SKIP() << absentMessage(start.drive);
  const DriveRun run = firstScans(start.drive, start.start, kStartFrames);
  ASSERT_GE(run.estimate.size(), kStartFrames);
  const PoseError second = poseErrorFromFirst(run.truth_at_instants, run.estimate, 1);
  const PoseError eleventh = poseErrorFromFirst(run.truth_at_instants, run.estimate, kStartFrames - 1);
  const PoseError tracked = trackedError(start.drive, start.start, kStartFrames - 1);
  std::cout << "drive " << start.drive << " from scan " << start.start << ": 2nd scan " << second.translation_m
            << " m, 11th " << eleventh.translation_m << " m off; the run from scan 0 over the same scans "
            << tracked.translation_m << " m; rotation " << eleventh.rotation_deg << " deg against "
            << tracked.rotation_deg << " deg" << std::endl;
  EXPECT_LT(second.translation_m, 0.10);
  EXPECT_LT(eleventh.translation_m, std::max(0.30, tracked.translation_m + 0.05));
  EXPECT_LT(eleventh.rotation_deg, tracked.rotation_deg + 0.1);
}

INSTANTIATE_TEST_SUITE_P(Drives, StartInMotion,
                         testing::Values(StartCase{"0027", 0}, StartCase{"0027", 60}, StartCase{"0027", 120},
                                         StartCase{"0027", 177}, StartCase{"0001", 0}, StartCase{"0001", 60},
                                         StartCase{"0002", 0}, StartCase{"0002", 60}, StartCase{"0002", 66},
                                         StartCase{"0005", 0}, StartCase{"0005", 60}, StartCase{"0005", 120},
                                         StartCase{"0005", 143}),
                         [](const auto& info) {
                           return std::string("drive_") + info.param.drive + "_scan_" + std::to_string(info.param.start);
                         });

}  // namespace
}  // namespace elo
