// A map as a PCD file: written binary (normal fields only for a map with normals), read back exactly;
// non-finite points skipped and counted, malformed files refused.
#include "elo/io/map_pcd.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <iterator>
#include <vector>

#include "elo/io/io_error.hpp"
#include "elo/io/pcd.hpp"
#include "temp_directory.hpp"

namespace elo {
namespace {

using test::TempDirectory;

MapCloud sampleMap() {
  MapCloud map;
  map.points = {Vec3f(1.5f, -2.25f, 0.125f), Vec3f(-1000.0f, 250.5f, -3.0f)};
  map.intensity = {12.0f, 0.5f};
  map.normals = {Vec3f(0, 0, 1), Vec3f::Zero()};
  return map;
}

TEST(MapPcd, WritesBinaryXyzIntensityAndNormals) {
  TempDirectory directory;
  const std::string path = directory.file("map.pcd");
  writeMapPcd(path, sampleMap());
  std::ifstream stream(path, std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(stream)), std::istreambuf_iterator<char>());
  EXPECT_NE(bytes.find("FIELDS x y z intensity normal_x normal_y normal_z\n"), std::string::npos) << bytes.substr(0, 300);
  EXPECT_NE(bytes.find("TYPE F F F F F F F\n"), std::string::npos);
  EXPECT_NE(bytes.find("POINTS 2\n"), std::string::npos);
  EXPECT_NE(bytes.find("DATA binary\n"), std::string::npos);
}

TEST(MapPcd, ReadsBackWhatItWrote) {
  TempDirectory directory;
  const std::string path = directory.file("map.pcd");
  const MapCloud written = sampleMap();
  writeMapPcd(path, written);
  const MapCloud read = readMapPcd(path);
  EXPECT_EQ(read.points, written.points);
  EXPECT_EQ(read.intensity, written.intensity);
  EXPECT_EQ(read.normals, written.normals);
  // Any PCD reader sees x y z intensity.
  const PointCloud scan = readPcd(path);
  EXPECT_EQ(scan.points, written.points);
  EXPECT_EQ(scan.intensity, written.intensity);
}

TEST(MapPcd, WritesAnEmptyMap) {
  TempDirectory directory;
  const std::string path = directory.file("empty.pcd");
  writeMapPcd(path, MapCloud{});
  EXPECT_EQ(readMapPcd(path).size(), 0u);
}

TEST(MapPcd, ReadsAScanWithoutNormalsAsAMapWithoutThem) {
  TempDirectory directory;
  const std::string path = directory.file("scan.pcd");
  PointCloud scan;
  scan.points = {Vec3f(1, 2, 3)};
  scan.intensity = {4};
  writePcd(path, scan);
  const MapCloud map = readMapPcd(path);
  ASSERT_EQ(map.size(), 1u);
  EXPECT_EQ(map.intensity, std::vector<float>{4.0f});
  EXPECT_FALSE(map.hasNormals());
  EXPECT_TRUE(map.normals.empty());  // localization estimates them at load
}

TEST(MapPcd, WritesNormalFieldsOnlyForAMapWithNormals) {
  TempDirectory directory;
  const std::string path = directory.file("bare.pcd");
  MapCloud bare = sampleMap();
  bare.normals.clear();
  writeMapPcd(path, bare);
  std::ifstream stream(path, std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(stream)), std::istreambuf_iterator<char>());
  EXPECT_NE(bytes.find("FIELDS x y z intensity\n"), std::string::npos) << bytes.substr(0, 300);
  const MapCloud read = readMapPcd(path);
  EXPECT_EQ(read.points, bare.points);
  EXPECT_EQ(read.intensity, bare.intensity);
  EXPECT_TRUE(read.normals.empty());
}

TEST(MapPcd, SkipsAndCountsNonFinitePointsAndReadsNormalsAsTheyAre) {
  TempDirectory directory;
  const std::string path = directory.file("nan.pcd");
  std::ofstream(path) << "VERSION .7\nFIELDS x y z normal_x normal_y normal_z\nSIZE 4 4 4 4 4 4\nTYPE F F F F F F\n"
                         "COUNT 1 1 1 1 1 1\nWIDTH 3\nHEIGHT 1\nPOINTS 3\nDATA ascii\n"
                         "1 2 3 0 0 1\nnan 2 3 0 0 1\n4 5 6 nan 0 2\n";
  size_t skipped = 0;
  const MapCloud map = readMapPcd(path, &skipped);
  EXPECT_EQ(skipped, 1u);
  EXPECT_EQ(map.points, (std::vector<Vec3f>{Vec3f(1, 2, 3), Vec3f(4, 5, 6)}));
  EXPECT_TRUE(map.intensity.empty());  // the file has none
  ASSERT_EQ(map.normals.size(), 2u);
  EXPECT_EQ(map.normals[0], Vec3f(0, 0, 1));
  EXPECT_TRUE(std::isnan(map.normals[1].x()));  // prepareMap() zeroes and counts it
  EXPECT_EQ(map.normals[1].z(), 2.0f);
}

TEST(MapPcd, SaysWhyAFileCannotBeReadOrWritten) {
  EXPECT_THROW(readMapPcd("/nonexistent/map.pcd"), IoError);
  EXPECT_THROW(writeMapPcd("/nonexistent/directory/map.pcd", sampleMap()), IoError);
  TempDirectory directory;
  const std::string path = directory.file("bad.pcd");
  std::ofstream(path) << "VERSION .7\nFIELDS a b c\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH 1\nHEIGHT 1\n"
                         "POINTS 1\nDATA ascii\n1 2 3\n";
  EXPECT_THROW(readMapPcd(path), IoError);
  std::ofstream(path) << "VERSION .7\nFIELDS x y z normal_x normal_y\nSIZE 4 4 4 4 4\nTYPE F F F F F\nCOUNT 1 1 1 1 1\n"
                         "WIDTH 1\nHEIGHT 1\nPOINTS 1\nDATA ascii\n1 2 3 0 1\n";
  EXPECT_THROW(readMapPcd(path), IoError) << "some normal fields but not all three";
}

}  // namespace
}  // namespace elo
