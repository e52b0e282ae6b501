// elo_run over a simulated sequence with scans it cannot read: a truncated or malformed scan is skipped,
// counted by reason and its pose line repeats the last pose, so that the lines still match the scans;
// --strict stops at such a scan with a non-zero exit, after writing the poses of the scans before it.
// --no-prefetch changes no pose. The same drive as a ROS 1 bag (kitti_to_bag) and a ROS 2 bag (our test
// writer) gives the directory's poses bit for bit; malformed, truncated and empty bags are clear errors or
// counted skips that keep the poses computed so far. --start plays from a later scan. The IMU from a bag's
// Imu topic (--imu-topic) gives the poses of the same drive's imu.txt, a ROS 2 bag's those of a ROS 1 bag.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <string>
#include <vector>

#include <rosbag/bag.h>
#include <sensor_msgs/Imu.h>

#include "../io/ros2_bag_writer.hpp"
#include "../io/temp_directory.hpp"
#include "cloud_conversion.hpp"
#include "imu_conversion.hpp"
#include "run_command.hpp"
#include "elo/io/kitti.hpp"
#include "elo/io/imu_file.hpp"
#include "elo/io/pcd.hpp"
#include "elo/io/ros2_bag.hpp"
#include "elo/io/sequence.hpp"

// An Imu message cut short after its header, as a broken driver or recorder could leave it: rosbag records
// it as a sensor_msgs/Imu.
namespace imu_test {
struct TruncatedImu {
  std_msgs::Header header;
};
}  // namespace imu_test

namespace ros {
namespace message_traits {
template <>
struct MD5Sum<imu_test::TruncatedImu> {
  static const char* value() { return MD5Sum<sensor_msgs::Imu>::value(); }
  static const char* value(const imu_test::TruncatedImu&) { return value(); }
};
template <>
struct DataType<imu_test::TruncatedImu> {
  static const char* value() { return DataType<sensor_msgs::Imu>::value(); }
  static const char* value(const imu_test::TruncatedImu&) { return value(); }
};
template <>
struct Definition<imu_test::TruncatedImu> {
  static const char* value() { return Definition<sensor_msgs::Imu>::value(); }
  static const char* value(const imu_test::TruncatedImu&) { return value(); }
};
}  // namespace message_traits

namespace serialization {
template <>
struct Serializer<imu_test::TruncatedImu> {
  template <typename Stream, typename T>
  inline static void allInOne(Stream& stream, T message) {
    stream.next(message.header);
  }
  ROS_DECLARE_ALLINONE_SERIALIZER
};
}  // namespace serialization
}  // namespace ros

namespace {

namespace fs = std::filesystem;

constexpr size_t kScans = 6;

using elo::test::CommandResult;
using elo::test::contains;
using elo::test::runCommand;

std::vector<std::string> lines(const std::string& path) {
  std::vector<std::string> result;
  std::ifstream stream(path);
  for (std::string line; std::getline(stream, line);) result.push_back(line);
  return result;
}

std::string scanPath(const fs::path& sequence, size_t index, const char* extension = ".bin") {
  char name[16];
  std::snprintf(name, sizeof(name), "%06zu", index);
  return (sequence / "velodyne" / (name + std::string(extension))).string();
}

// The largest difference between two KITTI pose files' numbers; infinity when their lines differ in count.
double largestDifference(const std::string& a, const std::string& b) {
  const std::vector<Eigen::Isometry3d> first = elo::readKittiPoses(a);
  const std::vector<Eigen::Isometry3d> second = elo::readKittiPoses(b);
  if (first.size() != second.size()) return std::numeric_limits<double>::infinity();
  double largest = 0.0;
  for (size_t i = 0; i < first.size(); ++i) {
    largest = std::max(largest, (first[i].matrix() - second[i].matrix()).cwiseAbs().maxCoeff());
  }
  return largest;
}

// Cuts a scan file short in the middle of a point, as an interrupted copy leaves it.
void truncate(const std::string& path) { fs::resize_file(path, fs::file_size(path) / 2 + 3); }

class EloRunCli : public testing::Test {
 protected:
  // One simulated drive for the whole suite; each test corrupts a copy of it.
  static void SetUpTestSuite() {
    drive_ = new elo::test::TempDirectory;
    const CommandResult simulated =
        runCommand(std::string(ELO_SIM_TOOL) + " --world urban --trajectory straight --sensor hdl64 --seed 3 --frames " +
                   std::to_string(kScans) + " --threads 2 --output " + drive_->file("sequence"));
    ASSERT_EQ(simulated.exit_code, 0) << simulated.output;
    const CommandResult intact = runEloRunOn(drive_->file("sequence"), drive_->file("intact.txt"));
    ASSERT_EQ(intact.exit_code, 0) << intact.output;
    intact_poses_ = lines(drive_->file("intact.txt"));
    ASSERT_EQ(intact_poses_.size(), kScans);
  }
  static void TearDownTestSuite() { delete drive_; }

  static CommandResult runEloRunOn(const std::string& sequence, const std::string& poses,
                                   const std::string& options = "") {
    return runCommand(std::string(ELO_RUN_TOOL) + " --input " + sequence + " --output " + poses + " --config " +
                      ELO_SOURCE_DIR + "/config/hdl64.yaml --threads 2 --quiet " + options);
  }

  void SetUp() override {
    sequence_ = directory_.path() / "sequence";
    fs::copy(drive_->path() / "sequence", sequence_, fs::copy_options::recursive);
  }

  CommandResult runEloRun(const std::string& options = "") const {
    return runEloRunOn(sequence_.string(), poses(), options);
  }
  std::string poses() const { return directory_.file("poses.txt"); }
  // elo_sim's 6-scan urban drive with a consumer IMU (imu.txt and imu.yaml beside the scans) in
  // `imu_drive`, with `more` of elo_sim's options.
  CommandResult simulateImuDrive(const std::string& more = "") const {
    return runCommand(std::string(ELO_SIM_TOOL) +
                      " --world urban --trajectory curves --sensor hdl64 --seed 3 --frames 6 --threads 2 "
                      "--imu consumer --output " + directory_.file("imu_drive") + more);
  }

  static elo::test::TempDirectory* drive_;
  static std::vector<std::string> intact_poses_;
  elo::test::TempDirectory directory_;
  fs::path sequence_;
};

elo::test::TempDirectory* EloRunCli::drive_ = nullptr;
std::vector<std::string> EloRunCli::intact_poses_;

TEST_F(EloRunCli, HelpDocumentsStrict) {
  const CommandResult result = runCommand(std::string(ELO_RUN_TOOL) + " --help");
  EXPECT_EQ(result.exit_code, 0);
  EXPECT_TRUE(contains(result.output, "--strict")) << result.output;
}

// A sigma_r too small for the beams' spacing leaves far points without normals: elo_run says so at start,
// naming the setting (the HDL-64E's beams, 0.5 deg apart at the median: 0.1 m reaches 11 m, 0.5 m 57 m).
TEST_F(EloRunCli, WarnsWhenFarPointsGetNoNormal) {
  const CommandResult narrow = runEloRun("--frames 1 --set normals.outlier_distance=0.1");
  EXPECT_EQ(narrow.exit_code, 0) << narrow.output;
  EXPECT_TRUE(contains(narrow.output, "warning: points beyond 11 m get no normal")) << narrow.output;
  EXPECT_TRUE(contains(narrow.output, "normals.outlier_distance is 0.10 m; set it to 0.3 m")) << narrow.output;
  const CommandResult papers = runEloRun("--frames 1");
  EXPECT_EQ(papers.exit_code, 0) << papers.output;
  EXPECT_FALSE(contains(papers.output, "get no normal")) << papers.output;
}

// The scans' clock jumps 2 s forward before scan 3 while the car drives on: elo_run says where, and that
// the motion was searched across the gap, and the poses stay those of the intact drive.
TEST_F(EloRunCli, AClockJumpIsToldAndSearchedAcross) {
  const fs::path times = sequence_ / "times.txt";
  const std::vector<std::string> stamps = lines(times.string());
  ASSERT_EQ(stamps.size(), kScans);
  {
    std::ofstream rewritten(times);
    for (size_t i = 0; i < kScans; ++i) rewritten << std::stod(stamps[i]) + (i >= 3 ? 2.0 : 0.0) << "\n";
  }
  const CommandResult result = runEloRun();
  ASSERT_EQ(result.exit_code, 0) << result.output;
  EXPECT_TRUE(contains(result.output, "scan 3: 2.10 s after the last scan (dropped scans or a clock jump)")) << result.output;
  EXPECT_TRUE(contains(result.output, "1 gap between scans (the motion searched across)")) << result.output;
  const std::vector<std::string> written = lines(poses());
  ASSERT_EQ(written.size(), kScans);
  EXPECT_LT(largestDifference(poses(), drive_->file("intact.txt")), 0.01);
}

TEST_F(EloRunCli, TruncatedLastScanIsSkippedAndRepeatsTheLastPose) {
  truncate(scanPath(sequence_, kScans - 1));
  const CommandResult result = runEloRun();
  ASSERT_EQ(result.exit_code, 0) << result.output;
  const std::vector<std::string> written = lines(poses());
  ASSERT_EQ(written.size(), kScans) << "one pose line per scan";
  for (size_t i = 0; i + 1 < kScans; ++i) EXPECT_EQ(written[i], intact_poses_[i]) << "scan " << i;
  EXPECT_EQ(written[kScans - 1], written[kScans - 2]);
  EXPECT_NE(written[kScans - 1], intact_poses_[kScans - 1]);
  EXPECT_TRUE(contains(result.output, "scan 5 skipped: scan file unreadable")) << result.output;
  EXPECT_TRUE(contains(result.output, "5 processed, 1 skipped (scan file unreadable)")) << result.output;
  EXPECT_TRUE(contains(result.output, "repeats the last pose")) << result.output;
}

TEST_F(EloRunCli, UnreadableScansInTheMiddleAndAtTheEndAreCountedTogether) {
  std::ofstream(scanPath(sequence_, 2), std::ios::trunc) << "not a scan";
  truncate(scanPath(sequence_, kScans - 1));
  const CommandResult result = runEloRun("--tum " + directory_.file("poses.tum"));
  ASSERT_EQ(result.exit_code, 0) << result.output;
  const std::vector<std::string> written = lines(poses());
  ASSERT_EQ(written.size(), kScans);
  EXPECT_EQ(written[0], intact_poses_[0]);
  EXPECT_EQ(written[1], intact_poses_[1]);
  EXPECT_EQ(written[2], written[1]) << "the unreadable scan repeats the last pose";
  EXPECT_NE(written[3], written[2]) << "the odometry goes on after the unreadable scan";
  EXPECT_EQ(written[5], written[4]);
  EXPECT_EQ(lines(directory_.file("poses.tum")).size(), kScans);
  EXPECT_TRUE(contains(result.output, "4 processed, 2 skipped (scan file unreadable)")) << result.output;
}

TEST_F(EloRunCli, MalformedPcdScanIsSkipped) {
  // The same drive as a directory of PCD scans, the fourth with a header that stops short.
  const fs::path pcd_sequence = directory_.path() / "pcd";
  fs::create_directories(pcd_sequence);
  const elo::Sequence bins(sequence_.string());
  for (size_t i = 0; i < kScans; ++i) {
    const std::string name = fs::path(scanPath(pcd_sequence, i, ".pcd")).filename().string();
    elo::writePcd((pcd_sequence / name).string(), bins.load(i));
  }
  fs::copy_file(sequence_ / "times.txt", pcd_sequence / "times.txt");
  std::ofstream(pcd_sequence / "000003.pcd", std::ios::trunc) << "# .PCD v0.7\nVERSION 0.7\nFIELDS x y z\n";
  const CommandResult result = runEloRunOn(pcd_sequence.string(), poses());
  ASSERT_EQ(result.exit_code, 0) << result.output;
  const std::vector<std::string> written = lines(poses());
  ASSERT_EQ(written.size(), kScans);
  EXPECT_EQ(written[3], written[2]);
  EXPECT_TRUE(contains(result.output, "scan 3 skipped: scan file unreadable")) << result.output;
  EXPECT_TRUE(contains(result.output, "1 skipped (scan file unreadable)")) << result.output;
}

TEST_F(EloRunCli, StrictStopsAtTheFirstUnreadableScanAndKeepsThePosesBeforeIt) {
  truncate(scanPath(sequence_, kScans - 1));
  const CommandResult result = runEloRun("--strict");
  EXPECT_EQ(result.exit_code, 1) << result.output;
  const std::vector<std::string> written = lines(poses());
  ASSERT_EQ(written.size(), kScans - 1) << "the poses computed before the unreadable scan";
  for (size_t i = 0; i < written.size(); ++i) EXPECT_EQ(written[i], intact_poses_[i]) << "scan " << i;
  EXPECT_TRUE(contains(result.output, "scan 5: ")) << result.output;
  EXPECT_TRUE(contains(result.output, "--strict")) << result.output;
}

TEST_F(EloRunCli, StrictRunOverGoodScansSucceeds) {
  const CommandResult result = runEloRun("--strict");
  ASSERT_EQ(result.exit_code, 0) << result.output;
  EXPECT_EQ(lines(poses()), intact_poses_);
}

// On the CUDA backend, where one is usable, the next scan's upload overlaps this scan's processing
// unless --no-prefetch; it changes no pose. Elsewhere both runs fall back to the CPU backend.
TEST_F(EloRunCli, PrefetchingChangesNoPose) {
  const std::string cuda = "--backend cuda --set runtime.backend_fallback=true ";
  const CommandResult prefetched = runEloRunOn(sequence_.string(), directory_.file("prefetched.txt"), cuda);
  ASSERT_EQ(prefetched.exit_code, 0) << prefetched.output;
  const CommandResult unprefetched = runEloRunOn(sequence_.string(), poses(), cuda + "--no-prefetch");
  ASSERT_EQ(unprefetched.exit_code, 0) << unprefetched.output;
  const std::vector<std::string> written = lines(poses());
  EXPECT_EQ(written.size(), kScans);
  EXPECT_EQ(lines(directory_.file("prefetched.txt")), written);
}

// The TUM trajectory's stamps (first column) are those of `scans`: the run played them.
void expectPlayedScans(const std::string& tum, const elo::Sequence& sequence, const std::vector<size_t>& scans) {
  const std::vector<std::string> written = lines(tum);
  ASSERT_EQ(written.size(), scans.size());
  for (size_t i = 0; i < scans.size(); ++i) EXPECT_NEAR(std::stod(written[i]), sequence.stamp(scans[i]), 1e-6) << i;
}

// --start N plays scan N first, at the origin, then every --stride-th scan after it, at most --frames of
// them: a bag cut mid-drive, or a node started on a moving car.
TEST_F(EloRunCli, StartPlaysFromTheGivenScanWithStrideAndFrames) {
  const elo::Sequence sequence(sequence_.string());
  const CommandResult cut = runEloRun("--start 2 --frames 3 --tum " + directory_.file("cut.tum"));
  ASSERT_EQ(cut.exit_code, 0) << cut.output;
  const std::vector<std::string> written = lines(poses());
  ASSERT_EQ(written.size(), 3u);
  EXPECT_EQ(written[0], intact_poses_[0]) << "the first played scan is at the origin";
  expectPlayedScans(directory_.file("cut.tum"), sequence, {2, 3, 4});
  const CommandResult strided = runEloRun("--start 1 --stride 2 --tum " + directory_.file("strided.tum"));
  ASSERT_EQ(strided.exit_code, 0) << strided.output;
  EXPECT_EQ(lines(poses()).size(), 3u);
  expectPlayedScans(directory_.file("strided.tum"), sequence, {1, 3, 5});
}

TEST_F(EloRunCli, StartBeyondTheInputOrWithReverseIsAUsageError) {
  const CommandResult beyond = runEloRun("--start 6");
  EXPECT_EQ(beyond.exit_code, 2) << beyond.output;
  EXPECT_TRUE(contains(beyond.output, "--start 6: the input has 6 scans")) << beyond.output;
  const CommandResult reverse = runEloRun("--start 2 --reverse");
  EXPECT_EQ(reverse.exit_code, 2) << reverse.output;
  EXPECT_TRUE(contains(reverse.output, "--start and --reverse cannot be combined")) << reverse.output;
}

// A reverse run over sweeps taken while the sensor moved: each sweep is mirrored as well, so that the
// forward and the reverse run close, whether the points are timed by a field or by their azimuth. With
// the sweeps left as recorded the reverse run deskewed them the wrong way: 0.095 m (azimuth) and 0.52 m
// (field) of gap over these 6.5 m.
TEST_F(EloRunCli, AReverseRunOfSweepsMirrorsThemAndClosesOnTheForwardRun) {
  for (const std::string convention : {"field", "azimuth"}) {
    const std::string sweeps = directory_.file("sweeps_" + convention);
    const CommandResult simulated = runCommand(
        std::string(ELO_SIM_TOOL) + " --world urban --trajectory curves --sensor vlp16 --seed 3 --frames 30 --threads 2 "
        "--deskewed 0 --time-convention " + convention + " --format pcd --output " + sweeps);
    ASSERT_EQ(simulated.exit_code, 0) << simulated.output;
    std::vector<Eigen::Isometry3d> last_poses;
    for (const std::string direction : {"", "--reverse"}) {
      const std::string poses = directory_.file("sweeps_" + convention + direction + ".txt");
      const CommandResult run = runCommand(std::string(ELO_RUN_TOOL) + " --input " + sweeps + " --output " + poses +
                                           " --config " + ELO_SOURCE_DIR + "/config/vlp16.yaml --threads 2 --quiet " +
                                           "--set deskew.time_source=" + convention + " " + direction);
      ASSERT_EQ(run.exit_code, 0) << run.output;
      last_poses.push_back(elo::readKittiPoses(poses).back());
    }
    // The forward run's last pose times the reverse run's is the identity for a perfect odometry.
    EXPECT_LT((last_poses[0] * last_poses[1]).translation().norm(), 0.03) << convention;
  }
  const CommandResult with_imu = runEloRun("--reverse --set imu.enabled=true");
  EXPECT_EQ(with_imu.exit_code, 2) << with_imu.output;
  EXPECT_TRUE(contains(with_imu.output, "--reverse cannot take an IMU")) << with_imu.output;
}

// kitti_to_bag's start time: the bag's header stamps are the sequence's times plus this.
constexpr double kBagStartTime = 1.0;

// Scan `i` of `sequence` as the bags written here carry it: in frame velodyne, kBagStartTime later.
sensor_msgs::PointCloud2 bagCloud(const elo::Sequence& sequence, size_t i) {
  elo::PointCloud cloud = sequence.load(i);
  cloud.stamp += kBagStartTime;
  return elo_ros::toPointCloud2(cloud, "velodyne");
}

CommandResult writeRos1Bag(const std::string& sequence, const std::string& bag) {
  return runCommand(std::string(KITTI_TO_BAG_TOOL) + " --input " + sequence + " --output " + bag +
                    " --poses-frame lidar");
}

// The sequence's scans as a ROS 2 bag, stamped as kitti_to_bag stamps them.
void writeRos2Bag(const std::string& sequence_path, const std::string& bag) {
  const elo::Sequence sequence(sequence_path);
  elo::test::Ros2BagWriter writer(bag);
  const int64_t topic = writer.addTopic("/points");
  for (size_t i = 0; i < sequence.size(); ++i) {
    const elo::test::Stamp stamp = elo::test::stampOf(sequence.stamp(i) + kBagStartTime);
    writer.write(topic, int64_t{stamp.sec} * 1000000000 + stamp.nanosec,
                 elo::test::encodeCdrPointCloud2(sequence.load(i), stamp));
  }
}

TEST_F(EloRunCli, Ros1BagGivesTheSequencesPosesBitForBit) {
  const std::string bag = directory_.file("drive.bag");
  const CommandResult written = writeRos1Bag(sequence_.string(), bag);
  ASSERT_EQ(written.exit_code, 0) << written.output;
  const CommandResult result = runEloRunOn(bag, poses(), "--tum " + directory_.file("poses.tum"));
  ASSERT_EQ(result.exit_code, 0) << result.output;
  EXPECT_EQ(lines(poses()), intact_poses_);
  EXPECT_TRUE(contains(result.output, "6 scans, 6 processed")) << result.output;
  // The TUM stamps are the clouds' header stamps.
  std::vector<double> stamps;
  elo::readTumPoses(directory_.file("poses.tum"), &stamps);
  const elo::Sequence sequence(sequence_.string());
  ASSERT_EQ(stamps.size(), kScans);
  for (size_t i = 0; i < kScans; ++i) EXPECT_NEAR(stamps[i], sequence.stamp(i) + kBagStartTime, 1e-6) << i;
}

TEST_F(EloRunCli, Ros2BagGivesTheSequencesPosesBitForBit) {
  writeRos2Bag(sequence_.string(), directory_.file("drive_ros2"));
  const CommandResult result = runEloRunOn(directory_.file("drive_ros2"), poses());
  ASSERT_EQ(result.exit_code, 0) << result.output;
  EXPECT_EQ(lines(poses()), intact_poses_);
}

TEST_F(EloRunCli, BagWithSeveralCloudTopicsNeedsTopic) {
  const std::string bag = directory_.file("two.bag");
  {
    const elo::Sequence sequence(sequence_.string());
    rosbag::Bag writer(bag, rosbag::bagmode::Write);
    for (size_t i = 0; i < sequence.size(); ++i) {
      const sensor_msgs::PointCloud2 message = bagCloud(sequence, i);
      writer.write("/front/points", message.header.stamp, message);
      if (i < 2) writer.write("/rear/points", message.header.stamp, message);
    }
  }
  const CommandResult ambiguous = runEloRunOn(bag, poses());
  EXPECT_EQ(ambiguous.exit_code, 1) << ambiguous.output;
  EXPECT_TRUE(contains(ambiguous.output, "/front/points (sensor_msgs/PointCloud2, 6 messages)")) << ambiguous.output;
  EXPECT_TRUE(contains(ambiguous.output, "/rear/points (sensor_msgs/PointCloud2, 2 messages)")) << ambiguous.output;
  EXPECT_TRUE(contains(ambiguous.output, "--topic")) << ambiguous.output;
  const CommandResult chosen = runEloRunOn(bag, poses(), "--topic /front/points");
  ASSERT_EQ(chosen.exit_code, 0) << chosen.output;
  EXPECT_EQ(lines(poses()), intact_poses_);
}

// A cloud whose data is shorter than its header promises, as a driver bug or a cut recording leaves it:
// skipped and counted under the conversion's reason, as the nodelet counts it; --strict stops there.
TEST_F(EloRunCli, MalformedCloudInABagIsSkippedAndCounted) {
  const std::string bag = directory_.file("malformed.bag");
  {
    const elo::Sequence sequence(sequence_.string());
    rosbag::Bag writer(bag, rosbag::bagmode::Write);
    for (size_t i = 0; i < sequence.size(); ++i) {
      sensor_msgs::PointCloud2 message = bagCloud(sequence, i);
      if (i == 2) message.data.resize(message.data.size() / 2);
      writer.write("/points", message.header.stamp, message);
    }
  }
  const CommandResult result = runEloRunOn(bag, poses());
  ASSERT_EQ(result.exit_code, 0) << result.output;
  const std::vector<std::string> written = lines(poses());
  ASSERT_EQ(written.size(), kScans);
  EXPECT_EQ(written[1], intact_poses_[1]);
  EXPECT_EQ(written[2], written[1]) << "the unusable cloud repeats the last pose";
  EXPECT_TRUE(contains(result.output, "scan 2 skipped: truncated data")) << result.output;
  EXPECT_TRUE(contains(result.output, "5 processed, 1 skipped (truncated data)")) << result.output;

  const CommandResult strict = runEloRunOn(bag, poses(), "--strict");
  EXPECT_EQ(strict.exit_code, 1) << strict.output;
  EXPECT_EQ(lines(poses()), std::vector<std::string>(intact_poses_.begin(), intact_poses_.begin() + 2));
}

TEST_F(EloRunCli, TruncatedAndEmptyRos1BagsAreClearErrors) {
  const std::string bag = directory_.file("cut.bag");
  ASSERT_EQ(writeRos1Bag(sequence_.string(), bag).exit_code, 0);
  fs::resize_file(bag, fs::file_size(bag) / 2);
  const CommandResult cut = runEloRunOn(bag, poses());
  EXPECT_EQ(cut.exit_code, 1) << cut.output;
  EXPECT_TRUE(contains(cut.output, "cut.bag")) << cut.output;
  EXPECT_TRUE(contains(cut.output, "rosbag reindex")) << cut.output;

  const std::string empty = directory_.file("empty.bag");
  { rosbag::Bag writer(empty, rosbag::bagmode::Write); }
  const CommandResult nothing = runEloRunOn(empty, poses());
  EXPECT_EQ(nothing.exit_code, 1) << nothing.output;
  EXPECT_TRUE(contains(nothing.output, "has no sensor_msgs/PointCloud2 topic; its topics: none")) << nothing.output;

  std::ofstream(directory_.file("drive.mcap")) << "\x89MCAP0\r\n";
  const CommandResult mcap = runEloRunOn(directory_.file("drive.mcap"), poses());
  EXPECT_EQ(mcap.exit_code, 1) << mcap.output;
  EXPECT_TRUE(contains(mcap.output, "ros2 bag convert")) << mcap.output;
}

// A ROS 2 bag cut short (a copy interrupted) whose message table SQLite can no longer follow is a clear
// error naming the damaged file. A message that does not decode is skipped and counted, or --strict stops
// at it; the poses before it are kept either way.
TEST_F(EloRunCli, TruncatedOrMalformedRos2Bag) {
  const std::string cut = directory_.file("cut_ros2");
  writeRos2Bag(sequence_.string(), cut);
  fs::resize_file(cut + "/cut_ros2_0.db3", fs::file_size(cut + "/cut_ros2_0.db3") / 2);
  const CommandResult truncated = runEloRunOn(cut, poses());
  EXPECT_EQ(truncated.exit_code, 1) << truncated.output;
  EXPECT_TRUE(contains(truncated.output, "cut_ros2_0.db3' is damaged")) << truncated.output;

  const std::string bag = directory_.file("bad_ros2");
  {
    const elo::Sequence sequence(sequence_.string());
    elo::test::Ros2BagWriter writer(bag);
    const int64_t topic = writer.addTopic("/points");
    for (size_t i = 0; i < sequence.size(); ++i) {
      const elo::test::Stamp stamp = elo::test::stampOf(sequence.stamp(i) + kBagStartTime);
      std::vector<uint8_t> message = elo::test::encodeCdrPointCloud2(sequence.load(i), stamp);
      if (i == 3) message.resize(message.size() - 1000);  // its point data cut short
      writer.write(topic, int64_t{stamp.sec} * 1000000000 + stamp.nanosec, message);
    }
  }
  const CommandResult result = runEloRunOn(bag, poses());
  ASSERT_EQ(result.exit_code, 0) << result.output;
  const std::vector<std::string> written = lines(poses());
  ASSERT_EQ(written.size(), kScans);
  for (size_t i = 0; i < 3; ++i) EXPECT_EQ(written[i], intact_poses_[i]) << i;
  EXPECT_EQ(written[3], written[2]);
  EXPECT_TRUE(contains(result.output, "scan 3 skipped: message unreadable")) << result.output;
  EXPECT_TRUE(contains(result.output, "5 processed, 1 skipped (message unreadable)")) << result.output;

  const CommandResult strict = runEloRunOn(bag, poses(), "--strict");
  EXPECT_EQ(strict.exit_code, 1) << strict.output;
  EXPECT_EQ(lines(poses()), std::vector<std::string>(intact_poses_.begin(), intact_poses_.begin() + 3));
}

// A simulated drive whose sensor moves during each sweep, each point's time in the clouds' `time` field
// (elo_sim --bag): elo_run deskews it from the bag as it does from the PCD scans beside it, which is
// what the nodelet does (test/ros/sim_deskew_test.cpp).
TEST_F(EloRunCli, BagWithPerPointTimesDeskewsAsTheScansOnDisk) {
  const std::string sequence = directory_.file("distorted");
  const std::string bag = directory_.file("distorted.bag");
  const CommandResult simulated = runCommand(
      std::string(ELO_SIM_TOOL) + " --world urban --trajectory curves --sensor vlp16 --seed 3 --frames 8 --threads 2 "
      "--deskewed 0 --time-convention field --format pcd --output " + sequence + " --bag " + bag);
  ASSERT_EQ(simulated.exit_code, 0) << simulated.output;
  const auto run = [&](const std::string& input, const std::string& output, const std::string& source) {
    return runCommand(std::string(ELO_RUN_TOOL) + " --input " + input + " --output " + output + " --config " +
                      ELO_SOURCE_DIR + "/config/vlp16.yaml --threads 2 --quiet --set deskew.time_source=" + source);
  };
  ASSERT_EQ(run(sequence, directory_.file("disk.txt"), "field").exit_code, 0);
  const CommandResult from_bag = run(bag, directory_.file("bag.txt"), "field");
  ASSERT_EQ(from_bag.exit_code, 0) << from_bag.output;
  EXPECT_EQ(lines(directory_.file("bag.txt")), lines(directory_.file("disk.txt")));
  ASSERT_EQ(run(bag, directory_.file("undeskewed.txt"), "none").exit_code, 0);
  EXPECT_NE(lines(directory_.file("undeskewed.txt")), lines(directory_.file("bag.txt"))) << "the times were used";
}

}  // namespace

// --map: the drive's map as a binary PCD when the run ends, and when it fails part-way (the scans before).
size_t mapPoints(const std::string& path) {
  std::ifstream stream(path, std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(stream)), std::istreambuf_iterator<char>());
  if (!contains(bytes, "FIELDS x y z intensity normal_x normal_y normal_z\n") || !contains(bytes, "DATA binary\n")) return 0;
  const size_t points = bytes.find("\nPOINTS ");
  return points == std::string::npos ? 0 : std::stoul(bytes.substr(points + 8));
}

TEST_F(EloRunCli, MapIsWrittenAtTheEndAndWhenTheRunFailsPartWay) {
  // Every scan into the map (map.scan_stride 1), so that the last one, which the failing run loses, is in
  // the whole run's map.
  const std::string every_scan = " --map-voxel 0.3 --set map.scan_stride=1";
  const std::string map = directory_.file("map.pcd");
  const CommandResult result = runEloRun("--map " + map + every_scan);
  ASSERT_EQ(result.exit_code, 0) << result.output;
  EXPECT_TRUE(contains(result.output, "map: ")) << result.output;
  const size_t whole = mapPoints(map);
  EXPECT_GT(whole, 5000u);

  truncate(scanPath(sequence_, kScans - 1));
  const std::string partial = directory_.file("partial.pcd");
  EXPECT_EQ(runEloRun("--strict --map " + partial + every_scan).exit_code, 1);
  const size_t before_failure = mapPoints(partial);
  EXPECT_GT(before_failure, 5000u) << "the map of the scans before the failure";
  EXPECT_LT(before_failure, whole) << "one scan fewer";
}

// The IMU from a directory (docs/imu.md): elo_sim --imu writes imu.txt and imu.yaml, elo_run takes the
// sensor's configuration and imu.yaml over it (--config twice) and turns every scan by the gyro; with
// imu.enabled and no imu.txt it stops, saying where it looked.
TEST_F(EloRunCli, ImuTxtBesideTheScansTurnsEveryScan) {
  const std::string drive = directory_.file("imu_drive");
  const CommandResult simulated = simulateImuDrive();
  ASSERT_EQ(simulated.exit_code, 0) << simulated.output;
  ASSERT_TRUE(fs::is_regular_file(drive + "/imu.txt"));
  const CommandResult with_imu = runEloRunOn(drive, poses(), "--config " + drive + "/imu.yaml");
  ASSERT_EQ(with_imu.exit_code, 0) << with_imu.output;
  EXPECT_TRUE(contains(with_imu.output, "every scan turned by the IMU")) << with_imu.output;
  EXPECT_EQ(lines(poses()).size(), 6u);
  fs::remove(drive + "/imu.txt");
  const CommandResult without_file = runEloRunOn(drive, poses(), "--config " + drive + "/imu.yaml");
  EXPECT_NE(without_file.exit_code, 0);
  EXPECT_TRUE(contains(without_file.output, "imu.txt")) << without_file.output;
}


// elo_sim --imu --bag writes the IMU twice: imu.txt beside the scans, sensor_msgs/Imu on the bag's /imu
// (stamped as its clouds, a second later). elo_run takes the bag's only Imu topic and gives the poses of
// the directory with its imu.txt, within the rounding of the bag's nanosecond stamps.
TEST_F(EloRunCli, ImuTopicOfABagGivesThePosesOfTheSameDrivesImuTxt) {
  const std::string drive = directory_.file("imu_drive");
  const std::string bag = directory_.file("imu_drive.bag");
  const CommandResult simulated = simulateImuDrive(" --format pcd --bag " + bag);
  ASSERT_EQ(simulated.exit_code, 0) << simulated.output;
  const std::string imu_yaml = "--config " + drive + "/imu.yaml";
  const CommandResult from_file = runEloRunOn(drive, directory_.file("from_file.txt"), imu_yaml);
  ASSERT_EQ(from_file.exit_code, 0) << from_file.output;
  EXPECT_TRUE(contains(from_file.output, "every scan turned by the IMU")) << from_file.output;
  const CommandResult from_bag = runEloRunOn(bag, directory_.file("from_bag.txt"), imu_yaml);
  ASSERT_EQ(from_bag.exit_code, 0) << from_bag.output;
  EXPECT_TRUE(contains(from_bag.output, "imu: bag '" + bag + "', topic /imu")) << from_bag.output;
  EXPECT_TRUE(contains(from_bag.output, "every scan turned by the IMU")) << from_bag.output;
  EXPECT_LT(largestDifference(directory_.file("from_file.txt"), directory_.file("from_bag.txt")), 1e-6);
  // Not the poses of the LiDAR alone: the gyro did turn these scans.
  const CommandResult lidar_only = runEloRunOn(bag, directory_.file("lidar_only.txt"));
  ASSERT_EQ(lidar_only.exit_code, 0) << lidar_only.output;
  EXPECT_GT(largestDifference(directory_.file("from_bag.txt"), directory_.file("lidar_only.txt")), 1e-6);
}

// The suite's straight drive as a bag with two IMUs that do not turn (as the drive does not): named, one
// of them turns every scan, its truncated message skipped and counted; unnamed, the run stops naming both.
TEST_F(EloRunCli, BagWithTwoImuTopicsNeedsImuTopicAndSkipsAMalformedMessage) {
  const std::string bag = directory_.file("two_imus.bag");
  {
    const elo::Sequence sequence(sequence_.string());
    rosbag::Bag writer(bag, rosbag::bagmode::Write);
    for (size_t i = 0; i < sequence.size(); ++i) {
      const sensor_msgs::PointCloud2 message = bagCloud(sequence, i);
      writer.write("/points", message.header.stamp, message);
    }
    const double end = sequence.stamp(sequence.size() - 1) + kBagStartTime + 0.2;
    for (int k = 0; kBagStartTime - 0.1 + k * 0.005 <= end; ++k) {
      elo::ImuSample sample;
      sample.stamp = kBagStartTime - 0.1 + k * 0.005;
      sample.specific_force = {0.0, 0.0, 9.81};
      const sensor_msgs::Imu message = elo_ros::imuMessageOf(sample, "imu");
      if (k == 20) {
        writer.write("/imu/a", message.header.stamp, imu_test::TruncatedImu{message.header});
      } else {
        writer.write("/imu/a", message.header.stamp, message);
      }
      writer.write("/imu/b", message.header.stamp, message);
    }
  }
  const CommandResult ambiguous = runEloRunOn(bag, poses(), "--set imu.enabled=true");
  EXPECT_EQ(ambiguous.exit_code, 1) << ambiguous.output;
  EXPECT_TRUE(contains(ambiguous.output, "several sensor_msgs/Imu topics: /imu/a (sensor_msgs/Imu, ")) << ambiguous.output;
  EXPECT_TRUE(contains(ambiguous.output, "/imu/b (sensor_msgs/Imu, ")) << ambiguous.output;
  EXPECT_TRUE(contains(ambiguous.output, "--imu-topic")) << ambiguous.output;

  const CommandResult chosen = runEloRunOn(bag, poses(), "--set imu.enabled=true --imu-topic /imu/a");
  ASSERT_EQ(chosen.exit_code, 0) << chosen.output;
  EXPECT_TRUE(contains(chosen.output, "warning: 1 IMU message skipped: Imu message unreadable")) << chosen.output;
  EXPECT_TRUE(contains(chosen.output, "IMU: 1 message skipped (Imu message unreadable)")) << chosen.output;
  EXPECT_TRUE(contains(chosen.output, "every scan turned by the IMU")) << chosen.output;
  EXPECT_EQ(lines(poses()).size(), kScans);

  const CommandResult missing = runEloRunOn(bag, poses(), "--set imu.enabled=true --imu-topic /imu/c");
  EXPECT_EQ(missing.exit_code, 1) << missing.output;
  EXPECT_TRUE(contains(missing.output, "has no sensor_msgs/Imu topic /imu/c")) << missing.output;
}

// A drive with its IMU as a ROS 1 bag and as a ROS 2 bag, both written here from the same directory (the
// same clouds, the same imu.txt samples, the same nanosecond stamps): the same poses bit for bit. The ROS
// 2 bag's Imu messages alternate the byte order, and it carries a second Imu topic and an Imu message cut
// short on the one read, between two samples: named with --imu-topic, that message is skipped and counted,
// saying what is wrong; unnamed, the run stops naming both topics.
TEST_F(EloRunCli, Ros2BagImuTopicGivesTheRos1BagsPosesBitForBit) {
  const std::string drive = directory_.file("imu_drive");
  const CommandResult simulated = simulateImuDrive();
  ASSERT_EQ(simulated.exit_code, 0) << simulated.output;
  const elo::Sequence sequence(drive);
  const std::vector<elo::ImuSample> samples = elo::readImuFile(drive + "/imu.txt");
  ASSERT_GT(samples.size(), 100u);
  const std::string ros1_bag = directory_.file("imu_drive.bag");
  const std::string ros2_bag = directory_.file("imu_drive_ros2");
  {
    rosbag::Bag ros1(ros1_bag, rosbag::bagmode::Write);
    elo::test::Ros2BagWriter ros2(ros2_bag);
    const int64_t points = ros2.addTopic("/points");
    const int64_t imu = ros2.addTopic("/imu", elo::kRos2ImuType);
    const int64_t other_imu = ros2.addTopic("/imu/other", elo::kRos2ImuType);
    const auto nanoseconds = [](elo::test::Stamp stamp) { return int64_t{stamp.sec} * 1000000000 + stamp.nanosec; };
    for (size_t i = 0; i < sequence.size(); ++i) {
      const sensor_msgs::PointCloud2 cloud = bagCloud(sequence, i);
      ros1.write("/points", cloud.header.stamp, cloud);
      const elo::test::Stamp stamp = elo::test::stampOf(sequence.stamp(i) + kBagStartTime);
      ros2.write(points, nanoseconds(stamp), elo::test::encodeCdrPointCloud2(sequence.load(i), stamp));
    }
    for (size_t k = 0; k < samples.size(); ++k) {
      elo::ImuSample sample = samples[k];
      sample.stamp += kBagStartTime;
      const sensor_msgs::Imu message = elo_ros::imuMessageOf(sample, "imu");
      ros1.write("/imu", message.header.stamp, message);
      const elo::test::Stamp stamp = elo::test::stampOf(sample.stamp);
      ASSERT_EQ(stamp.sec, static_cast<int32_t>(message.header.stamp.sec));
      ASSERT_EQ(stamp.nanosec, message.header.stamp.nsec);
      ros2.write(imu, nanoseconds(stamp), elo::test::encodeCdrImu(sample, stamp, k % 2 == 1));
      if (k == samples.size() / 2) {
        std::vector<uint8_t> cut = elo::test::encodeCdrImu(sample, stamp);
        cut.resize(cut.size() / 2);
        ros2.write(imu, nanoseconds(stamp), cut);
        ros2.write(other_imu, nanoseconds(stamp), elo::test::encodeCdrImu(sample, stamp));
      }
    }
  }
  const std::string imu_yaml = "--config " + drive + "/imu.yaml";
  const CommandResult from_ros1 = runEloRunOn(ros1_bag, directory_.file("from_ros1.txt"), imu_yaml);
  ASSERT_EQ(from_ros1.exit_code, 0) << from_ros1.output;
  const CommandResult from_ros2 =
      runEloRunOn(ros2_bag, directory_.file("from_ros2.txt"), imu_yaml + " --imu-topic /imu");
  ASSERT_EQ(from_ros2.exit_code, 0) << from_ros2.output;
  EXPECT_TRUE(contains(from_ros2.output, "imu: bag '" + ros2_bag + "', topic /imu, " + std::to_string(samples.size()) +
                                             " samples"))
      << from_ros2.output;
  EXPECT_TRUE(contains(from_ros2.output, "warning: 1 IMU message skipped: Imu message unreadable (ROS 2 bag '"))
      << from_ros2.output;
  EXPECT_TRUE(contains(from_ros2.output, "malformed CDR Imu")) << from_ros2.output;
  EXPECT_TRUE(contains(from_ros2.output, "IMU: 1 message skipped (Imu message unreadable)")) << from_ros2.output;
  EXPECT_TRUE(contains(from_ros2.output, "every scan turned by the IMU")) << from_ros2.output;
  EXPECT_EQ(lines(directory_.file("from_ros2.txt")), lines(directory_.file("from_ros1.txt")));
  EXPECT_EQ(lines(directory_.file("from_ros2.txt")).size(), 6u);

  const CommandResult ambiguous = runEloRunOn(ros2_bag, poses(), imu_yaml);
  EXPECT_EQ(ambiguous.exit_code, 1) << ambiguous.output;
  EXPECT_TRUE(contains(ambiguous.output, "several sensor_msgs/msg/Imu topics: /imu (sensor_msgs/msg/Imu, " +
                                             std::to_string(samples.size() + 1) + " messages), /imu/other"))
      << ambiguous.output;
}

// No Imu topic in the bag: a warning, and the LiDAR alone for every scan, each counted. --imu-topic needs
// imu.enabled, and a bag to name a topic of.
TEST_F(EloRunCli, BagWithoutImuTopicRunsOnTheLidarAlone) {
  const std::string bag = directory_.file("drive.bag");
  ASSERT_EQ(writeRos1Bag(sequence_.string(), bag).exit_code, 0);
  const CommandResult result = runEloRunOn(bag, poses(), "--set imu.enabled=true");
  ASSERT_EQ(result.exit_code, 0) << result.output;
  EXPECT_TRUE(contains(result.output, "has no sensor_msgs/Imu topic: the LiDAR alone")) << result.output;
  EXPECT_TRUE(contains(result.output, std::to_string(kScans) + " on the LiDAR-only prior (no IMU samples over the scan)"))
      << result.output;
  EXPECT_EQ(lines(poses()).size(), kScans);

  const CommandResult not_enabled = runEloRunOn(bag, poses(), "--imu-topic /imu");
  EXPECT_EQ(not_enabled.exit_code, 2) << not_enabled.output;
  EXPECT_TRUE(contains(not_enabled.output, "--imu-topic needs imu.enabled")) << not_enabled.output;
  const CommandResult directory = runEloRun("--set imu.enabled=true --imu-topic /imu");
  EXPECT_EQ(directory.exit_code, 1) << directory.output;
  EXPECT_TRUE(contains(directory.output, "is not a bag")) << directory.output;
}
