// ROS 2 bags without ROS 2: the CDR decoder of sensor_msgs/msg/PointCloud2 on messages our test encoder
// writes (either byte order, every truncation), and elo::Ros2Bag on bags written with SQLite as
// `ros2 bag record` writes them: stamp order, topic choice, and clear errors for what it cannot read.
#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>

#include "elo/io/cdr_point_cloud2.hpp"
#include "elo/io/io_error.hpp"
#include "elo/io/ros2_bag.hpp"
#include "ros2_bag_writer.hpp"
#include "temp_directory.hpp"
#include "test_helpers.hpp"

namespace {

using elo::test::contains;
using elo::test::encodeCdrPointCloud2;
using elo::test::errorOf;
using elo::test::Ros2BagWriter;
using elo::test::stampOf;

elo::PointCloud smallCloud(float offset = 0.0f) {
  elo::PointCloud cloud;
  cloud.points = {{1.0f + offset, 2.0f, 3.0f}, {-4.5f, 0.25f + offset, 7.0f}, {10.0f, -3.0f, -1.5f}};
  cloud.intensity = {10.0f, 20.0f, 30.0f};
  cloud.ring = {3, 63, 0};
  cloud.time = {-0.05f, 0.0f, 0.049f};
  return cloud;
}

TEST(CdrPointCloud2, DecodesWhatTheEncoderWritesInEitherByteOrder) {
  const elo::PointCloud cloud = smallCloud();
  for (const bool big_endian : {false, true}) {
    SCOPED_TRACE(big_endian ? "big-endian" : "little-endian");
    const std::vector<uint8_t> bytes = encodeCdrPointCloud2(cloud, {1234, 500000000}, big_endian, big_endian);
    const elo::PointCloud2View view = elo::decodeCdrPointCloud2(bytes.data(), bytes.size());
    EXPECT_EQ(view.stamp, 1234.5);
    EXPECT_EQ(elo::decodeCdrStamp(bytes.data(), bytes.size()), 1234.5);
    EXPECT_EQ(view.width, 3u);
    EXPECT_EQ(view.height, 1u);
    ASSERT_EQ(view.fields.size(), 6u);
    EXPECT_EQ(view.fields[4].name, "ring");
    EXPECT_EQ(view.fields[4].offset, 16u);
    EXPECT_EQ(view.fields[4].datatype, elo::point_field::kUint16);
    EXPECT_EQ(view.point_step, 24u);
    const elo::ConvertedCloud converted = elo::convertPointCloud2(view);
    ASSERT_TRUE(converted.usable()) << converted.detail;
    EXPECT_EQ(converted.cloud.points, cloud.points);
    EXPECT_EQ(converted.cloud.intensity, cloud.intensity);
    EXPECT_EQ(converted.cloud.ring, cloud.ring);
    EXPECT_EQ(converted.cloud.time, cloud.time);
  }
}

// Every prefix of a message is rejected with an error that says where it ends, never read past its end.
TEST(CdrPointCloud2, EveryTruncationIsAClearError) {
  const std::vector<uint8_t> bytes = encodeCdrPointCloud2(smallCloud(), {1, 2});
  for (size_t size = 0; size < bytes.size(); ++size) {
    const std::vector<uint8_t> prefix(bytes.begin(), bytes.begin() + size);  // exactly `size` bytes on the heap
    const std::string error = errorOf([&] { elo::decodeCdrPointCloud2(prefix.data(), prefix.size()); });
    EXPECT_FALSE(error.empty()) << size << " bytes decoded";
    EXPECT_TRUE(contains(error, "malformed CDR PointCloud2")) << error;
  }
}

TEST(CdrPointCloud2, RejectsOtherEncapsulationsAndCorruptLengths) {
  std::vector<uint8_t> bytes = encodeCdrPointCloud2(smallCloud(), {1, 2});
  std::vector<uint8_t> xcdr2 = bytes;
  xcdr2[1] = 0x07;  // XCDR2 little-endian
  EXPECT_TRUE(contains(errorOf([&] { elo::decodeCdrPointCloud2(xcdr2.data(), xcdr2.size()); }), "not plain CDR"));
  // The field count (after stamp, frame_id "velodyne", height, width) claims four billion fields.
  std::vector<uint8_t> huge = bytes;
  const size_t fields_count = 4 + 8 + 4 + 9 + 3 + 4 + 4;  // header, stamp, length, "velodyne\0", padding, height, width
  std::memset(huge.data() + fields_count, 0xFF, 4);
  const std::string error = errorOf([&] { elo::decodeCdrPointCloud2(huge.data(), huge.size()); });
  EXPECT_TRUE(contains(error, "fields says 4294967295 elements")) << error;
}

class Ros2BagTest : public testing::Test {
 protected:
  std::string bag(const std::string& name) const { return directory_.file(name); }
  elo::test::TempDirectory directory_;
};

TEST_F(Ros2BagTest, ReadsTheCloudsInHeaderStampOrder) {
  {
    Ros2BagWriter writer(bag("drive"));
    const int64_t points = writer.addTopic("/points");
    writer.addTopic("/imu", "sensor_msgs/msg/Imu");
    // Recorded out of stamp order, as a bag records clouds that arrive late.
    for (const double stamp : {100.2, 100.0, 100.1}) {
      writer.write(points, 5, encodeCdrPointCloud2(smallCloud(static_cast<float>(stamp - 100.0)), stampOf(stamp)));
    }
  }
  ASSERT_TRUE(elo::isRos2Bag(bag("drive")));
  const elo::Ros2Bag reader(bag("drive"), "");
  ASSERT_EQ(reader.size(), 3u);
  EXPECT_EQ(reader.stamp(0), 100.0);
  EXPECT_EQ(reader.stamp(1), elo::stampSeconds(100, 100000000));
  EXPECT_EQ(reader.stamp(2), elo::stampSeconds(100, 200000000));
  const elo::LoadedScan scan = reader.read(2);
  EXPECT_EQ(scan.cloud.stamp, reader.stamp(2));
  EXPECT_EQ(scan.cloud.points, smallCloud(static_cast<float>(100.2 - 100.0)).points);
  EXPECT_TRUE(contains(reader.describe(), "topic /points"));
}

TEST_F(Ros2BagTest, SeveralCloudTopicsNeedTopicAndTheErrorListsThem) {
  {
    Ros2BagWriter writer(bag("two"));
    const int64_t front = writer.addTopic("/front/points");
    const int64_t rear = writer.addTopic("/rear/points");
    writer.write(front, 1, encodeCdrPointCloud2(smallCloud(), stampOf(1.0)));
    writer.write(rear, 1, encodeCdrPointCloud2(smallCloud(), stampOf(1.0)));
    writer.write(rear, 2, encodeCdrPointCloud2(smallCloud(), stampOf(2.0)));
  }
  const std::string error = errorOf([&] { elo::Ros2Bag(bag("two"), ""); });
  EXPECT_TRUE(contains(error, "/front/points (sensor_msgs/msg/PointCloud2, 1 messages)")) << error;
  EXPECT_TRUE(contains(error, "/rear/points (sensor_msgs/msg/PointCloud2, 2 messages)")) << error;
  EXPECT_TRUE(contains(error, "--topic")) << error;
  EXPECT_EQ(elo::Ros2Bag(bag("two"), "/rear/points").size(), 2u);
  EXPECT_TRUE(contains(errorOf([&] { elo::Ros2Bag(bag("two"), "/nope"); }), "no sensor_msgs/msg/PointCloud2 topic /nope"));
}

TEST_F(Ros2BagTest, EmptyBagsAndMcapAreClearErrors) {
  { Ros2BagWriter(bag("empty")).addTopic("/points"); }
  EXPECT_TRUE(contains(errorOf([&] { elo::Ros2Bag(bag("empty"), ""); }), "holds no message"));
  { Ros2BagWriter(bag("no_clouds")).addTopic("/imu", "sensor_msgs/msg/Imu"); }
  EXPECT_TRUE(contains(errorOf([&] { elo::Ros2Bag(bag("no_clouds"), ""); }), "/imu (sensor_msgs/msg/Imu, 0 messages)"));
  std::filesystem::create_directories(bag("mcap"));
  std::ofstream(bag("mcap/metadata.yaml")) << "rosbag2_bagfile_information:\n  storage_identifier: mcap\n";
  std::ofstream(bag("mcap/mcap_0.mcap")) << "\x89MCAP0\r\n";
  EXPECT_TRUE(contains(errorOf([&] { elo::Ros2Bag(bag("mcap"), ""); }), "ros2 bag convert"));
}

// A message that is not a PointCloud2, or one whose points are cut short, is an UnusableScan with its
// reason; the messages around it still read.
TEST_F(Ros2BagTest, AMalformedMessageIsAnUnusableScan) {
  {
    Ros2BagWriter writer(bag("bad"));
    const int64_t points = writer.addTopic("/points");
    writer.write(points, 1, encodeCdrPointCloud2(smallCloud(), stampOf(1.0)));
    std::vector<uint8_t> cut = encodeCdrPointCloud2(smallCloud(), stampOf(2.0));
    cut.resize(cut.size() - 20);
    writer.write(points, 2, cut);
    writer.write(points, 3, encodeCdrPointCloud2(smallCloud(), stampOf(3.0)));
  }
  const elo::Ros2Bag reader(bag("bad"), "");
  ASSERT_EQ(reader.size(), 3u);
  EXPECT_EQ(reader.stamp(1), 2.0) << "the header stamp is read from the message's first bytes";
  EXPECT_NO_THROW(reader.read(0));
  try {
    reader.read(1);
    FAIL() << "a truncated message was read";
  } catch (const elo::UnusableScan& error) {
    EXPECT_EQ(error.reason(), "message unreadable");
    EXPECT_TRUE(contains(error.what(), "data says 72 elements, but only 53 bytes follow")) << error.what();
  }
  EXPECT_NO_THROW(reader.read(2));
}

}  // namespace
