#include "elo/io/pcd.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>

#include "elo/io/io_error.hpp"
#include "temp_directory.hpp"
#include "test_helpers.hpp"

namespace elo {
namespace {

using test::TempDirectory;

std::string realScan(const std::string& name) {
  return std::string(ELO_SHARED_DATA) + "/real/hdl64_drive_a/" + name;
}

// The first `count` float32 after the `DATA binary` header line (the data README: the payload is laid
// out as a KITTI .bin; PCL's writer may pad the file after it).
std::vector<float> binaryPayload(const std::string& path, size_t count) {
  std::ifstream stream(path, std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(stream)), std::istreambuf_iterator<char>());
  const std::string marker = "DATA binary\n";
  const size_t start = bytes.find(marker) + marker.size();
  if (bytes.size() < start + count * sizeof(float)) {
    ADD_FAILURE() << path << " holds fewer than " << count << " floats after its header";
    return {};
  }
  std::vector<float> payload(count);
  std::memcpy(payload.data(), bytes.data() + start, count * sizeof(float));
  return payload;
}

TEST(Pcd, RealHdl64ScanHasEveryPoint) {
  const std::string path = realScan("000000.pcd");
  if (!std::filesystem::exists(path)) {
    GTEST_SKIP() << "shared data absent: " << path;
  }
  size_t skipped = 1;
  const PointCloud cloud = readPcd(path, &skipped);
  EXPECT_EQ(skipped, 0u);
  ASSERT_EQ(cloud.size(), 123398u);
  ASSERT_EQ(cloud.intensity.size(), 123398u);
  EXPECT_TRUE(cloud.ring.empty());
  EXPECT_TRUE(cloud.time.empty());
  const std::vector<float> payload = binaryPayload(path, 4 * cloud.size());
  ASSERT_EQ(payload.size(), 4 * cloud.size());
  for (size_t i = 0; i < cloud.size(); i += 997) {
    EXPECT_EQ(cloud.points[i], Vec3f(payload[4 * i], payload[4 * i + 1], payload[4 * i + 2])) << "point " << i;
    EXPECT_EQ(cloud.intensity[i], payload[4 * i + 3]) << "point " << i;
  }
}

TEST(Pcd, WriteThenReadIsExactWithRingAndTime) {
  TempDirectory directory;
  PointCloud cloud = test::randomCloud(500, 11);
  for (size_t i = 0; i < cloud.size(); ++i) {
    cloud.ring.push_back(static_cast<uint16_t>(i % 64));
    cloud.time.push_back(static_cast<float>(i) * 1e-4f);
  }
  writePcd(directory.file("scan.pcd"), cloud);
  size_t skipped = 1;
  const PointCloud read = readPcd(directory.file("scan.pcd"), &skipped);
  EXPECT_EQ(skipped, 0u);
  test::expectSamePoints(cloud, read);
  EXPECT_EQ(read.ring, cloud.ring);
  EXPECT_EQ(read.time, cloud.time);
}

TEST(Pcd, EmptyCloudRoundTrips) {
  TempDirectory directory;
  writePcd(directory.file("empty.pcd"), PointCloud());
  size_t skipped = 1;
  EXPECT_EQ(readPcd(directory.file("empty.pcd"), &skipped).size(), 0u);
  EXPECT_EQ(skipped, 0u);
}

TEST(Pcd, NonFinitePointsAreSkippedAndCounted) {
  TempDirectory directory;
  PointCloud cloud = test::randomCloud(100, 12);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const float inf = std::numeric_limits<float>::infinity();
  cloud.points[3] = Vec3f(nan, nan, nan);
  cloud.points[50] = Vec3f(1.0f, inf, 2.0f);
  cloud.points[99] = Vec3f(0.0f, 0.0f, nan);
  writePcd(directory.file("scan.pcd"), cloud);

  size_t skipped = 0;
  const PointCloud read = readPcd(directory.file("scan.pcd"), &skipped);
  EXPECT_EQ(skipped, 3u);
  ASSERT_EQ(read.size(), 97u);
  ASSERT_EQ(read.intensity.size(), 97u);
  EXPECT_EQ(read.points[3], cloud.points[4]);  // the survivors keep their order and their intensity
  EXPECT_EQ(read.intensity[3], cloud.intensity[4]);
  EXPECT_EQ(read.points[96], cloud.points[98]);
}

TEST(Pcd, SkippedPointsWarnWhenNotCountedByTheCaller) {
  TempDirectory directory;
  PointCloud cloud = test::randomCloud(10, 13);
  cloud.points[0].x() = std::numeric_limits<float>::quiet_NaN();
  writePcd(directory.file("scan.pcd"), cloud);
  testing::internal::CaptureStderr();
  const PointCloud read = readPcd(directory.file("scan.pcd"));
  const std::string warning = testing::internal::GetCapturedStderr();
  EXPECT_EQ(read.size(), 9u);
  EXPECT_NE(warning.find("skipped 1 points"), std::string::npos) << warning;
  EXPECT_NE(warning.find(directory.file("scan.pcd")), std::string::npos) << warning;
}

TEST(Pcd, OusterStyleFieldsConvert) {
  // float64 coordinates, uint16 intensity, uint32 `t` in nanoseconds, uint8 ring, an organised NaN.
  TempDirectory directory;
  const std::string path = directory.file("ouster.pcd");
  test::writeText(path,
                  "# .PCD v0.7 - Point Cloud Data file format\n"
                  "VERSION 0.7\n"
                  "FIELDS x y z intensity t ring\n"
                  "SIZE 8 8 8 2 4 1\n"
                  "TYPE F F F U U U\n"
                  "COUNT 1 1 1 1 1 1\n"
                  "WIDTH 3\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS 3\nDATA ascii\n"
                  "1.5 -2.25 0.125 300 50000000 7\n"
                  "nan nan nan 0 60000000 8\n"
                  "10 20 30 65535 99000000 127\n");
  size_t skipped = 0;
  const PointCloud cloud = readPcd(path, &skipped);
  EXPECT_EQ(skipped, 1u);
  ASSERT_EQ(cloud.size(), 2u);
  EXPECT_EQ(cloud.points[0], Vec3f(1.5f, -2.25f, 0.125f));
  EXPECT_EQ(cloud.intensity, (std::vector<float>{300.0f, 65535.0f}));
  EXPECT_EQ(cloud.ring, (std::vector<uint16_t>{7, 127}));
  ASSERT_EQ(cloud.time.size(), 2u);
  EXPECT_FLOAT_EQ(cloud.time[0], 0.05f);
  EXPECT_FLOAT_EQ(cloud.time[1], 0.099f);
}

TEST(Pcd, FloatTimeFieldIsSeconds) {
  TempDirectory directory;
  const std::string path = directory.file("velodyne.pcd");
  test::writeText(path,
                  "VERSION 0.7\nFIELDS x y z time\nSIZE 4 4 4 4\nTYPE F F F F\nCOUNT 1 1 1 1\n"
                  "WIDTH 1\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS 1\nDATA ascii\n1 2 3 0.0625\n");
  const PointCloud cloud = readPcd(path);
  EXPECT_TRUE(cloud.intensity.empty());
  EXPECT_EQ(cloud.time, std::vector<float>{0.0625f});
}

TEST(Pcd, MissingCoordinateFieldThrowsNamingIt) {
  TempDirectory directory;
  const std::string path = directory.file("xy.pcd");
  test::writeText(path,
                  "VERSION 0.7\nFIELDS x y\nSIZE 4 4\nTYPE F F\nCOUNT 1 1\n"
                  "WIDTH 1\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS 1\nDATA ascii\n1 2\n");
  test::expectThrowContaining<IoError>([&] { readPcd(path); }, {path, "field 'z'"});
}

TEST(Pcd, MissingFileThrowsNamingIt) {
  test::expectThrowContaining<IoError>([] { readPcd("/nonexistent/scan.pcd"); }, {"/nonexistent/scan.pcd"});
}

TEST(Pcd, GarbageThrowsNamingTheFile) {
  TempDirectory directory;
  const std::string path = directory.file("garbage.pcd");
  test::writeText(path, "this is not a point cloud\n");
  test::expectThrowContaining<IoError>([&] { readPcd(path); }, {path, "not a PCD file"});
}

std::string xyzHeader(const std::string& size, uint64_t points, const std::string& data) {
  return "VERSION 0.7\nFIELDS x y z\nSIZE " + size + "\nTYPE F F F\nCOUNT 1 1 1\nWIDTH " +
         std::to_string(points) + "\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS " + std::to_string(points) +
         "\nDATA " + data + "\n";
}

template <typename T>
std::string bytesOf(const std::vector<T>& values) {
  return std::string(reinterpret_cast<const char*>(values.data()), values.size() * sizeof(T));
}

TEST(Pcd, BinaryCompressedReadsFieldByField) {
  // PCL's layout: compressed and uncompressed sizes, then LZF data holding all x, all y, all z. Here the
  // LZF stream is one literal run: a control byte of length - 1, then the 24 bytes themselves.
  TempDirectory directory;
  const std::string path = directory.file("compressed.pcd");
  const std::string fields_in_blocks = bytesOf(std::vector<float>{1.0f, 4.0f, 2.0f, 5.0f, 3.0f, 6.0f});
  const std::string lzf = std::string(1, static_cast<char>(fields_in_blocks.size() - 1)) + fields_in_blocks;
  test::writeText(path, xyzHeader("4 4 4", 2, "binary_compressed") +
                            bytesOf(std::vector<uint32_t>{static_cast<uint32_t>(lzf.size()), 24}) + lzf);
  const PointCloud cloud = readPcd(path);
  ASSERT_EQ(cloud.size(), 2u);
  EXPECT_EQ(cloud.points[0], Vec3f(1.0f, 2.0f, 3.0f));
  EXPECT_EQ(cloud.points[1], Vec3f(4.0f, 5.0f, 6.0f));
}

// PCL's own reader writes past its buffer on this header (found by fuzzing); ours names the field.
TEST(Pcd, SizeThatContradictsTypeThrowsNamingTheField) {
  TempDirectory directory;
  const std::string path = directory.file("bad.pcd");
  test::writeText(path, xyzHeader("4 4 1", 1, "ascii") + "1 2 3\n");
  test::expectThrowContaining<IoError>([&] { readPcd(path); }, {path, "field 'z'", "SIZE 1"});
}

TEST(Pcd, TruncatedDataThrowsWithoutAllocatingWhatTheHeaderClaims) {
  TempDirectory directory;
  const std::string path = directory.file("truncated.pcd");
  test::writeText(path, xyzHeader("4 4 4", 4000000000, "binary") + bytesOf(std::vector<float>{1, 2, 3}));
  test::expectThrowContaining<IoError>([&] { readPcd(path); }, {path, "truncated", "4000000000 points"});
  test::writeText(path, xyzHeader("4 4 4", 4000000000, "ascii") + "1 2 3\n");
  test::expectThrowContaining<IoError>([&] { readPcd(path); }, {path, "truncated: 1 of 4000000000"});
}

TEST(Pcd, AsciiValueOfTheWrongTypeThrowsNamingTheLine) {
  TempDirectory directory;
  const std::string path = directory.file("bad.pcd");
  test::writeText(path,
                  "FIELDS x y z ring\nSIZE 4 4 4 2\nTYPE F F F U\nWIDTH 2\nPOINTS 2\nDATA ascii\n"
                  "1 2 3 4\n1 2 3 -4\n");
  test::expectThrowContaining<IoError>([&] { readPcd(path); }, {path + ":8", "'-4'", "field 'ring'"});
}

}  // namespace
}  // namespace elo
