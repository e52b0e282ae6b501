#include "elo/io/sequence.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <stdexcept>
#include <vector>

#include "elo/io/io_error.hpp"
#include "elo/io/kitti.hpp"
#include "elo/io/pcd.hpp"
#include "temp_directory.hpp"
#include "test_helpers.hpp"

namespace elo {
namespace {

namespace fs = std::filesystem;
using test::expectThrowContaining;
using test::TempDirectory;
using test::writeText;

std::vector<Eigen::Isometry3d> forwardPoses(size_t count) {
  std::vector<Eigen::Isometry3d> poses(count, Eigen::Isometry3d::Identity());
  for (size_t i = 0; i < count; ++i) poses[i].translation().z() = 0.8 * static_cast<double>(i);
  return poses;
}

// DIR/velodyne/00000i.bin for i < count, with times.txt, calib.txt and poses.txt beside velodyne/.
std::vector<PointCloud> writeKittiSequence(const TempDirectory& directory, size_t count) {
  fs::create_directory(directory.path() / "velodyne");
  std::vector<PointCloud> clouds;
  for (size_t i = 0; i < count; ++i) {
    clouds.push_back(test::randomCloud(100 + i, static_cast<unsigned>(i)));
    writeKittiBin(directory.file("velodyne/00000" + std::to_string(i) + ".bin"), clouds.back());
  }
  writeTimes(directory.file("times.txt"), {0.0, 0.1037359, 0.2073669});
  Eigen::Isometry3d tr = Eigen::Isometry3d::Identity();
  tr.translation() = Eigen::Vector3d(0.1, -0.2, 0.3);
  writeKittiCalibration(directory.file("calib.txt"), tr);
  writeKittiPoses(directory.file("poses.txt"), forwardPoses(count));
  return clouds;
}

TEST(Sequence, KittiLayout) {
  TempDirectory directory;
  const std::vector<PointCloud> clouds = writeKittiSequence(directory, 3);
  const Sequence sequence(directory.path().string());
  ASSERT_EQ(sequence.size(), 3u);
  EXPECT_EQ(sequence.path(2), directory.file("velodyne/000002.bin"));
  const PointCloud scan = sequence.load(1);
  test::expectSamePoints(clouds[1], scan);
  EXPECT_EQ(scan.stamp, 0.1037359);
  EXPECT_EQ(sequence.stamp(2), 0.2073669);
  ASSERT_TRUE(sequence.hasCalibration());
  EXPECT_EQ(sequence.calibration().translation(), Eigen::Vector3d(0.1, -0.2, 0.3));
  ASSERT_TRUE(sequence.hasGroundTruth());
  ASSERT_EQ(sequence.groundTruth().size(), 3u);
  EXPECT_EQ(sequence.groundTruth()[2].translation().z(), 1.6);
}

TEST(Sequence, PcdDirectorySortedByNameAt10Hz) {
  TempDirectory directory;
  const PointCloud first = test::randomCloud(30, 1);
  const PointCloud second = test::randomCloud(40, 2);
  writePcd(directory.file("scan_b.pcd"), second);
  writePcd(directory.file("scan_a.pcd"), first);
  writeText(directory.file("notes.md"), "not a scan\n");
  const Sequence sequence(directory.path().string());
  ASSERT_EQ(sequence.size(), 2u);
  test::expectSamePoints(first, sequence.load(0));
  const PointCloud scan = sequence.load(1);
  test::expectSamePoints(second, scan);
  EXPECT_DOUBLE_EQ(scan.stamp, 0.1);
  EXPECT_FALSE(sequence.hasCalibration());
  EXPECT_FALSE(sequence.hasGroundTruth());
  expectThrowContaining<IoError>([&] { sequence.calibration(); }, {"no calib.txt"});
  expectThrowContaining<IoError>([&] { sequence.groundTruth(); }, {"no poses.txt"});
}

TEST(Sequence, FlatBinDirectory) {
  TempDirectory directory;
  const PointCloud cloud = test::randomCloud(20, 3);
  writeKittiBin(directory.file("000000.bin"), cloud);
  const Sequence sequence(directory.path().string());
  ASSERT_EQ(sequence.size(), 1u);
  size_t skipped = 1;
  test::expectSamePoints(cloud, sequence.load(0, &skipped));
  EXPECT_EQ(skipped, 0u);
}

TEST(Sequence, PcdNonFinitePointsAreCounted) {
  TempDirectory directory;
  PointCloud cloud = test::randomCloud(20, 4);
  cloud.points[5].y() = std::numeric_limits<float>::quiet_NaN();
  writePcd(directory.file("000000.pcd"), cloud);
  size_t skipped = 0;
  EXPECT_EQ(Sequence(directory.path().string()).load(0, &skipped).size(), 19u);
  EXPECT_EQ(skipped, 1u);
}

TEST(Sequence, MissingDirectoryThrowsNamingIt) {
  expectThrowContaining<IoError>([] { Sequence("/nonexistent/sequence"); }, {"/nonexistent/sequence", "does not exist"});
}

TEST(Sequence, DirectoryWithoutScansThrows) {
  TempDirectory directory;
  writeText(directory.file("times.txt"), "0\n");
  expectThrowContaining<IoError>([&] { Sequence(directory.path().string()); },
                                 {directory.path().string(), "no scans"});
  fs::create_directory(directory.path() / "velodyne");
  expectThrowContaining<IoError>([&] { Sequence(directory.path().string()); }, {"velodyne", "no .bin scans"});
}

TEST(Sequence, MixedFormatsThrow) {
  TempDirectory directory;
  writeKittiBin(directory.file("000000.bin"), test::randomCloud(5, 5));
  writePcd(directory.file("000001.pcd"), test::randomCloud(5, 6));
  expectThrowContaining<IoError>([&] { Sequence(directory.path().string()); }, {"mixes .pcd and .bin"});
}

TEST(Sequence, TimesCountMismatchThrowsWithBothCounts) {
  TempDirectory directory;
  writeKittiSequence(directory, 3);
  writeTimes(directory.file("times.txt"), {0.0, 0.1});
  expectThrowContaining<IoError>([&] { Sequence(directory.path().string()); },
                                 {directory.file("times.txt"), "2 entries", "3 scans"});
}

TEST(Sequence, PosesCountMismatchThrowsWithBothCounts) {
  TempDirectory directory;
  writeKittiSequence(directory, 3);
  writeKittiPoses(directory.file("poses.txt"), forwardPoses(4));
  expectThrowContaining<IoError>([&] { Sequence(directory.path().string()); },
                                 {directory.file("poses.txt"), "4 entries", "3 scans"});
}

TEST(Sequence, UnparsableTimesNameTheLine) {
  TempDirectory directory;
  writeKittiSequence(directory, 3);
  writeText(directory.file("times.txt"), "0\n0.1\nabc\n");
  expectThrowContaining<IoError>([&] { Sequence(directory.path().string()); },
                                 {directory.file("times.txt") + ":3", "'abc' is not a number"});
}

TEST(Sequence, MalformedBinThrowsOnLoadNamingTheFile) {
  TempDirectory directory;
  writeKittiSequence(directory, 3);
  writeText(directory.file("velodyne/000001.bin"), std::string(20, '\0'));
  const Sequence sequence(directory.path().string());
  EXPECT_NO_THROW(sequence.load(0));
  expectThrowContaining<IoError>([&] { sequence.load(1); }, {"000001.bin", "multiple of 16"});
}

TEST(Sequence, IndexOutOfRangeThrows) {
  TempDirectory directory;
  writeKittiSequence(directory, 3);
  const Sequence sequence(directory.path().string());
  EXPECT_THROW(sequence.load(3), std::out_of_range);
  EXPECT_THROW(sequence.stamp(3), std::out_of_range);
}

// Seven flat .bin scans recorded at uneven intervals.
Sequence writeUnevenlyTimedScans(const TempDirectory& directory) {
  for (unsigned i = 0; i < 7; ++i) writeKittiBin(directory.file("00000" + std::to_string(i) + ".bin"), test::randomCloud(10, i));
  writeTimes(directory.file("times.txt"), {0.0, 0.1, 0.21, 0.3, 0.42, 0.5, 0.61});
  return Sequence(directory.path().string());
}

void expectPlayed(const std::vector<PlayedScan>& played, const std::vector<size_t>& indices,
                  const std::vector<double>& stamps) {
  ASSERT_EQ(played.size(), indices.size());
  for (size_t i = 0; i < played.size(); ++i) {
    EXPECT_EQ(played[i].index, indices[i]) << "played scan " << i;
    EXPECT_NEAR(played[i].stamp, stamps[i], 1e-12) << "played scan " << i;
  }
}

TEST(PlayOrder, AStrideTakesEveryKthScanAtItsRecordedTime) {
  TempDirectory directory;
  const Sequence sequence = writeUnevenlyTimedScans(directory);
  expectPlayed(playOrder(sequence, 1, false), {0, 1, 2, 3, 4, 5, 6}, {0.0, 0.1, 0.21, 0.3, 0.42, 0.5, 0.61});
  expectPlayed(playOrder(sequence, 3, false), {0, 3, 6}, {0.0, 0.3, 0.61});
  expectPlayed(playOrder(sequence, 2, false, 2), {0, 2}, {0.0, 0.21});
  expectPlayed(playOrder(sequence, 2, false, 0, 3), {3, 5}, {0.3, 0.5});  // from scan 3: elo_run --start
  expectPlayed(playOrder(sequence, 1, false, 2, 4), {4, 5}, {0.42, 0.5});
  EXPECT_THROW(playOrder(sequence, 0, false), std::invalid_argument);
}

TEST(PlayOrder, AReverseRunPlaysLastToFirstWithTimeStillAdvancingByTheRecordedIntervals) {
  TempDirectory directory;
  const Sequence sequence = writeUnevenlyTimedScans(directory);
  expectPlayed(playOrder(sequence, 1, true), {6, 5, 4, 3, 2, 1, 0}, {0.0, 0.11, 0.19, 0.31, 0.4, 0.51, 0.61});
  expectPlayed(playOrder(sequence, 3, true), {6, 3, 0}, {0.0, 0.31, 0.61});
  expectPlayed(playOrder(sequence, 1, true, 2), {6, 5}, {0.0, 0.11});
}

TEST(PlayOrder, AReverseRunMirrorsEachSweep) {
  TempDirectory directory;
  const Sequence sequence = writeUnevenlyTimedScans(directory);
  const std::vector<float> recorded = {-0.05f, 0.0f, 0.03f};
  PointCloud forward;
  forward.time = recorded;
  asPlayed(playOrder(sequence, 1, false).back(), forward);
  EXPECT_EQ(forward.time, recorded);
  EXPECT_DOUBLE_EQ(forward.stamp, 0.61);
  PointCloud reversed;
  reversed.time = recorded;
  asPlayed(playOrder(sequence, 1, true).back(), reversed);
  EXPECT_EQ(reversed.time, (std::vector<float>{0.05f, 0.0f, -0.03f}));
  EXPECT_DOUBLE_EQ(reversed.stamp, 0.61);
  SensorConfig sensor;
  ASSERT_TRUE(sensor.clockwise);
  reverseSweepDirection(sensor);
  EXPECT_FALSE(sensor.clockwise);
}

TEST(Sequence, RealHdl64Drive) {
  const std::string path = std::string(ELO_SHARED_DATA) + "/real/hdl64_drive_a";
  if (!fs::is_directory(path)) {
    GTEST_SKIP() << "shared data absent: " << path;
  }
  const Sequence sequence(path);
  ASSERT_EQ(sequence.size(), 60u);
  EXPECT_EQ(fs::path(sequence.path(59)).filename(), "000059.pcd");
  EXPECT_EQ(sequence.load(0).size(), 123398u);
  EXPECT_DOUBLE_EQ(sequence.stamp(59), 5.9);
}

}  // namespace
}  // namespace elo
