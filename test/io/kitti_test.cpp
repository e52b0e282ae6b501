#include "elo/io/kitti.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <random>
#include <sstream>

#include "elo/io/io_error.hpp"
#include "temp_directory.hpp"
#include "test_helpers.hpp"

namespace elo {
namespace {

using test::expectThrowContaining;
using test::TempDirectory;
using test::writeText;

// KITTI odometry sequences 00-02: velodyne -> left camera (data README).
const char* const kKittiTrText =
    "4.276802385584e-04 -9.999672484946e-01 -8.084491683471e-03 -1.198459927713e-02 "
    "-7.210626507497e-03 8.081198471645e-03 -9.999413164504e-01 -5.403984729748e-02 "
    "9.999738645903e-01 4.859485810390e-04 -7.206933692422e-03 -2.921968648686e-01";

Eigen::Isometry3d kittiTr() {
  Eigen::Isometry3d tr = Eigen::Isometry3d::Identity();
  tr.matrix().topRows<3>() << 4.276802385584e-04, -9.999672484946e-01, -8.084491683471e-03, -1.198459927713e-02,
      -7.210626507497e-03, 8.081198471645e-03, -9.999413164504e-01, -5.403984729748e-02, 9.999738645903e-01,
      4.859485810390e-04, -7.206933692422e-03, -2.921968648686e-01;
  return tr;
}

std::vector<Eigen::Isometry3d> randomPoses(size_t count, unsigned seed) {
  std::srand(seed);  // Eigen's Random() draws from std::rand
  std::vector<Eigen::Isometry3d> poses;
  for (size_t i = 0; i < count; ++i) {
    Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
    pose.linear() = Eigen::Quaterniond::UnitRandom().toRotationMatrix();
    pose.translation() = 1000.0 * Eigen::Vector3d::Random();
    poses.push_back(pose);
  }
  return poses;
}

// Over the 3x4 [R|t] a pose file holds.
double maxAbsDifference(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b) {
  return (a.matrix().topRows<3>() - b.matrix().topRows<3>()).cwiseAbs().maxCoeff();
}

TEST(KittiBin, WriteThenReadIsExact) {
  TempDirectory directory;
  const PointCloud cloud = test::randomCloud(1000, 1);
  writeKittiBin(directory.file("scan.bin"), cloud);
  EXPECT_EQ(std::filesystem::file_size(directory.file("scan.bin")), 1000u * 16u);
  test::expectSamePoints(cloud, readKittiBin(directory.file("scan.bin")));
}

TEST(KittiBin, CloudWithoutIntensityIsWrittenWithZeros) {
  TempDirectory directory;
  PointCloud cloud = test::randomCloud(10, 2);
  cloud.intensity.clear();
  writeKittiBin(directory.file("scan.bin"), cloud);
  const PointCloud read = readKittiBin(directory.file("scan.bin"));
  EXPECT_EQ(read.intensity, std::vector<float>(10, 0.0f));
}

TEST(KittiBin, SizeNotMultipleOf16ThrowsNamingTheFile) {
  TempDirectory directory;
  const std::string path = directory.file("broken.bin");
  writeText(path, std::string(17, 'x'));
  expectThrowContaining<IoError>([&] { readKittiBin(path); }, {path, "17 bytes", "multiple of 16"});
}

TEST(KittiBin, ReadsFromAStream) {
  const std::vector<float> values = {1.0f, 2.0f, 3.0f, 0.5f, -4.0f, 5.0f, 6.0f, 0.25f};
  std::istringstream stream(std::string(reinterpret_cast<const char*>(values.data()), values.size() * sizeof(float)));
  const PointCloud cloud = readKittiBin(stream, "memory");
  ASSERT_EQ(cloud.size(), 2u);
  EXPECT_EQ(cloud.points[1], Vec3f(-4.0f, 5.0f, 6.0f));
  EXPECT_EQ(cloud.intensity, (std::vector<float>{0.5f, 0.25f}));
}

// A directory opens and seeks like a file of 2^63 bytes; it must not size a buffer.
TEST(KittiBin, DirectoryThrowsNamingIt) {
  TempDirectory directory;
  expectThrowContaining<IoError>([&] { readKittiBin(directory.path().string()); },
                                 {directory.path().string(), "not a regular file"});
}

TEST(KittiBin, MissingFileThrowsNamingIt) {
  expectThrowContaining<IoError>([] { readKittiBin("/nonexistent/000000.bin"); },
                                 {"/nonexistent/000000.bin", "cannot open"});
}

TEST(KittiPoses, WriteThenReadKeepsFullPrecision) {
  TempDirectory directory;
  const std::vector<Eigen::Isometry3d> poses = randomPoses(50, 3);
  writeKittiPoses(directory.file("poses.txt"), poses);
  const std::vector<Eigen::Isometry3d> read = readKittiPoses(directory.file("poses.txt"));
  ASSERT_EQ(read.size(), poses.size());
  for (size_t i = 0; i < poses.size(); ++i) {
    EXPECT_LT(maxAbsDifference(read[i], poses[i]), 1e-9) << "pose " << i;
  }
}

TEST(KittiPoses, WrongNumberCountNamesTheLine) {
  TempDirectory directory;
  const std::string path = directory.file("poses.txt");
  writeText(path, "1 0 0 0 0 1 0 0 0 0 1 0\n1 0 0 0 0 1 0 0 0 0 1\n");
  expectThrowContaining<IoError>([&] { readKittiPoses(path); }, {path + ":2", "expected 12 numbers, found 11"});
}

TEST(KittiPoses, NonNumberNamesTheLineAndToken) {
  TempDirectory directory;
  const std::string path = directory.file("poses.txt");
  writeText(path, "\n1 0 0 0 0 1 0 0 0 0 1 0\n1 0 0 zero 0 1 0 0 0 0 1 0\n");
  expectThrowContaining<IoError>([&] { readKittiPoses(path); }, {path + ":3", "'zero' is not a number"});
}

TEST(KittiPoses, ReadsTheRealSequence00) {
  const std::string path = std::string(ELO_SHARED_DATA) + "/kitti_gt/poses/00.txt";
  if (!std::filesystem::exists(path)) {
    GTEST_SKIP() << "shared data absent: " << path;
  }
  const std::vector<Eigen::Isometry3d> poses = readKittiPoses(path);
  ASSERT_EQ(poses.size(), 4541u);
  EXPECT_LT(maxAbsDifference(poses.front(), Eigen::Isometry3d::Identity()), 1e-6);  // 7 digits in the file
  EXPECT_NEAR(poses[1].translation().z(), 0.8586941, 1e-12);
}

TEST(KittiTimes, WriteThenReadIsExact) {
  TempDirectory directory;
  const std::vector<double> stamps = {0.0, 0.1037359, 0.2073669, 123456.789012345678};
  writeTimes(directory.file("times.txt"), stamps);
  EXPECT_EQ(readTimes(directory.file("times.txt")), stamps);
}

TEST(KittiTimes, TwoNumbersOnALineNameTheLine) {
  TempDirectory directory;
  const std::string path = directory.file("times.txt");
  writeText(path, "0\n0.1 0.2\n");
  expectThrowContaining<IoError>([&] { readTimes(path); }, {path + ":2", "expected 1 numbers, found 2"});
}

TEST(TumPoses, WriteThenReadKeepsThePoses) {
  TempDirectory directory;
  const std::vector<Eigen::Isometry3d> poses = randomPoses(20, 4);
  std::vector<double> stamps;
  for (size_t i = 0; i < poses.size(); ++i) stamps.push_back(1.5e9 + 0.1 * static_cast<double>(i));
  writeTumPoses(directory.file("tum.txt"), stamps, poses);
  std::vector<double> read_stamps;
  const std::vector<Eigen::Isometry3d> read = readTumPoses(directory.file("tum.txt"), &read_stamps);
  EXPECT_EQ(read_stamps, stamps);
  ASSERT_EQ(read.size(), poses.size());
  for (size_t i = 0; i < poses.size(); ++i) {
    EXPECT_LT(maxAbsDifference(read[i], poses[i]), 1e-12) << "pose " << i;
  }
}

TEST(TumPoses, StampCountMismatchThrows) {
  TempDirectory directory;
  expectThrowContaining<IoError>([&] { writeTumPoses(directory.file("tum.txt"), {0.0}, randomPoses(2, 5)); },
                                 {"1 stamps for 2 poses"});
}

TEST(KittiCalibration, ParsesTheTrOfSequences00To02) {
  TempDirectory directory;
  const std::string path = directory.file("calib.txt");
  writeText(path,
            "P0: 7.188560000000e+02 0.000000000000e+00 6.071928000000e+02 0.000000000000e+00 0.000000000000e+00 "
            "7.188560000000e+02 1.852157000000e+02 0.000000000000e+00 0.000000000000e+00 0.000000000000e+00 "
            "1.000000000000e+00 0.000000000000e+00\n"
            "Tr: " + std::string(kKittiTrText) + "\n");
  const Eigen::Isometry3d tr = readKittiCalibration(path);
  EXPECT_EQ(tr.matrix(), kittiTr().matrix());
}

TEST(KittiCalibration, AcceptsTrVeloToCam) {
  TempDirectory directory;
  const std::string path = directory.file("calib.txt");
  writeText(path, "Tr_velo_to_cam: " + std::string(kKittiTrText) + "\n");
  EXPECT_EQ(readKittiCalibration(path).matrix(), kittiTr().matrix());
}

TEST(KittiCalibration, MissingTrThrowsNamingTheFile) {
  TempDirectory directory;
  const std::string path = directory.file("calib.txt");
  writeText(path, "P0: 1 0 0 0 0 1 0 0 0 0 1 0\n");
  expectThrowContaining<IoError>([&] { readKittiCalibration(path); }, {path, "no 'Tr:'"});
}

TEST(KittiCalibration, ShortTrNamesTheLine) {
  TempDirectory directory;
  const std::string path = directory.file("calib.txt");
  writeText(path, "P0: 1 0 0 0 0 1 0 0 0 0 1 0\nTr: 1 0 0\n");
  expectThrowContaining<IoError>([&] { readKittiCalibration(path); }, {path + ":2", "12 numbers, found 3"});
}

TEST(KittiCalibration, WriteThenReadKeepsTrInTheDevkitLayout) {
  TempDirectory directory;
  const std::string path = directory.file("calib.txt");
  writeKittiCalibration(path, kittiTr());
  EXPECT_EQ(readKittiCalibration(path).matrix(), kittiTr().matrix());
  std::ifstream stream(path);
  std::vector<std::string> labels;
  for (std::string line; std::getline(stream, line);) labels.push_back(line.substr(0, line.find(':')));
  EXPECT_EQ(labels, (std::vector<std::string>{"P0", "P1", "P2", "P3", "Tr"}));
}

TEST(FrameConversion, LidarToCameraConjugatesByTr) {
  const std::vector<Eigen::Isometry3d> lidar = randomPoses(5, 6);
  const std::vector<Eigen::Isometry3d> camera = lidarToCamera(lidar, kittiTr());
  for (size_t i = 0; i < lidar.size(); ++i) {
    const Eigen::Isometry3d expected(kittiTr().matrix() * lidar[i].matrix() * kittiTr().matrix().inverse());
    EXPECT_LT(maxAbsDifference(camera[i], expected), 1e-9);
  }
}

TEST(FrameConversion, LidarToCameraThenBackIsIdentity) {
  const std::vector<Eigen::Isometry3d> lidar = randomPoses(20, 7);
  const std::vector<Eigen::Isometry3d> round_trip = cameraToLidar(lidarToCamera(lidar, kittiTr()), kittiTr());
  ASSERT_EQ(round_trip.size(), lidar.size());
  for (size_t i = 0; i < lidar.size(); ++i) {
    EXPECT_LT(maxAbsDifference(round_trip[i], lidar[i]), 1e-9) << "pose " << i;
  }
}

TEST(FrameConversion, CameraForwardIsLidarForward) {
  // Driving 1 m along the camera's z (forward) is driving 1 m along the LiDAR's x.
  Eigen::Isometry3d camera_motion = Eigen::Isometry3d::Identity();
  camera_motion.translation() = Eigen::Vector3d(0, 0, 1);
  const Eigen::Isometry3d lidar_motion = cameraToLidar({camera_motion}, kittiTr()).front();
  EXPECT_NEAR(lidar_motion.translation().x(), 1.0, 1e-3);
  EXPECT_NEAR(lidar_motion.translation().y(), 0.0, 2e-2);
}

}  // namespace
}  // namespace elo
