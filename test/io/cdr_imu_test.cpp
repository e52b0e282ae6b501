// The CDR decoder of sensor_msgs/msg/Imu on buffers laid out by hand (every field at the byte offset the
// CDR rules give it, in either byte order), every truncation and a foreign encapsulation; and
// elo::readRos2BagImu on bags written with SQLite as `ros2 bag record` writes them.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <functional>

#include "elo/io/cdr_imu.hpp"
#include "elo/io/io_error.hpp"
#include "elo/io/ros2_bag.hpp"
#include "ros2_bag_writer.hpp"
#include "temp_directory.hpp"
#include "test_helpers.hpp"

namespace {

using elo::test::contains;
using elo::test::errorOf;

// sensor_msgs/msg/Imu with frame_id "imu_link" (9 bytes with its NUL), byte offsets from the buffer's
// start: the 4-byte encapsulation header, then header.stamp (sec at 4, nanosec at 8), the frame_id's length
// at 12 and its characters at 16..24, 3 bytes of padding to the doubles' 8-byte alignment (counted from
// byte 4, so at 28), the orientation (4 doubles), its covariance (9), angular_velocity (3), its covariance
// (9), linear_acceleration (3), its covariance (9).
constexpr size_t kOrientation = 28;
constexpr size_t kAngularVelocity = kOrientation + 13 * 8;
constexpr size_t kAngularVelocityCovariance = kAngularVelocity + 3 * 8;
constexpr size_t kLinearAcceleration = kAngularVelocityCovariance + 9 * 8;
constexpr size_t kSize = kLinearAcceleration + 12 * 8;  // 324

template <typename T>
void put(std::vector<uint8_t>& bytes, size_t at, T value, bool big_endian) {
  std::memcpy(bytes.data() + at, &value, sizeof(T));
  if (big_endian != elo::hostIsBigEndian()) std::reverse(bytes.begin() + at, bytes.begin() + at + sizeof(T));
}

std::vector<uint8_t> handBuiltImu(bool big_endian, double angular_velocity_covariance0 = 0.0) {
  std::vector<uint8_t> bytes(kSize, 0);
  bytes[1] = big_endian ? 0 : 1;
  put<int32_t>(bytes, 4, 1700000000, big_endian);
  put<uint32_t>(bytes, 8, 250000000, big_endian);
  put<uint32_t>(bytes, 12, 9, big_endian);
  std::memcpy(bytes.data() + 16, "imu_link", 9);
  put<double>(bytes, kOrientation + 3 * 8, 1.0, big_endian);  // w
  put<double>(bytes, kOrientation + 4 * 8, -1.0, big_endian);  // orientation_covariance[0]: none
  const double rates[3] = {0.125, -3.5, 1e-3};
  const double forces[3] = {-0.0625, 9.80665, 123.456};
  for (int axis = 0; axis < 3; ++axis) {
    put<double>(bytes, kAngularVelocity + axis * 8, rates[axis], big_endian);
    put<double>(bytes, kLinearAcceleration + axis * 8, forces[axis], big_endian);
  }
  put<double>(bytes, kAngularVelocityCovariance, angular_velocity_covariance0, big_endian);
  return bytes;
}

TEST(CdrImu, DecodesAHandBuiltMessageExactlyInEitherByteOrder) {
  for (const bool big_endian : {false, true}) {
    SCOPED_TRACE(big_endian ? "big-endian" : "little-endian");
    const std::vector<uint8_t> bytes = handBuiltImu(big_endian);
    const elo::CdrImu imu = elo::decodeCdrImu(bytes.data(), bytes.size());
    EXPECT_EQ(imu.stamp, elo::stampSeconds(1700000000, 250000000));
    EXPECT_EQ(imu.angular_velocity, Eigen::Vector3d(0.125, -3.5, 1e-3));
    EXPECT_EQ(imu.linear_acceleration, Eigen::Vector3d(-0.0625, 9.80665, 123.456));
    EXPECT_TRUE(imu.has_angular_velocity);
  }
}

// The test encoder (ros2_bag_writer.hpp, which writes the bags of the tests) lays the message out as the
// hand-built buffer does.
TEST(CdrImu, TheTestEncoderWritesTheSameLayout) {
  elo::ImuSample sample;
  sample.angular_velocity = {0.125, -3.5, 1e-3};
  sample.specific_force = {-0.0625, 9.80665, 123.456};
  for (const bool big_endian : {false, true}) {
    std::vector<uint8_t> encoded = elo::test::encodeCdrImu(sample, {1700000000, 250000000}, big_endian);
    std::vector<uint8_t> hand_built = handBuiltImu(big_endian);
    ASSERT_EQ(encoded.size(), kSize - 8);  // frame "imu": 5 characters and 3 bytes of padding fewer
    const elo::CdrImu imu = elo::decodeCdrImu(encoded.data(), encoded.size());
    EXPECT_EQ(imu.angular_velocity, sample.angular_velocity);
    EXPECT_EQ(imu.linear_acceleration, sample.specific_force);
    // From the orientation on, the same bytes.
    EXPECT_TRUE(std::equal(encoded.begin() + (kOrientation - 8), encoded.end(), hand_built.begin() + kOrientation));
  }
}

TEST(CdrImu, NoAngularVelocityIsTold) {
  const std::vector<uint8_t> bytes = handBuiltImu(false, -1.0);
  EXPECT_FALSE(elo::decodeCdrImu(bytes.data(), bytes.size()).has_angular_velocity);
}

// Every prefix of a message is rejected with an error naming the field it ends in, never read past its end.
TEST(CdrImu, EveryTruncationIsAClearError) {
  const std::vector<uint8_t> bytes = handBuiltImu(false);
  for (size_t size = 0; size < bytes.size(); ++size) {
    const std::vector<uint8_t> prefix(bytes.begin(), bytes.begin() + size);  // exactly `size` bytes on the heap
    const std::string error = errorOf([&] { elo::decodeCdrImu(prefix.data(), prefix.size()); });
    EXPECT_TRUE(contains(error, "malformed CDR Imu")) << size << " bytes: " << error;
  }
  const std::vector<uint8_t> cut(bytes.begin(), bytes.begin() + kLinearAcceleration + 4);
  EXPECT_EQ(errorOf([&] { elo::decodeCdrImu(cut.data(), cut.size()); }),
            "malformed CDR Imu (byte 228 of 232): truncated in linear_acceleration: 8 bytes needed, 4 left");
}

TEST(CdrImu, OtherEncapsulationsAreClearErrors) {
  std::vector<uint8_t> xcdr2 = handBuiltImu(false);
  xcdr2[1] = 7;  // PL_CDR2_LE
  EXPECT_TRUE(contains(errorOf([&] { elo::decodeCdrImu(xcdr2.data(), xcdr2.size()); }),
                       "encapsulation 0,7 is not plain CDR"));
}

// A bag with two Imu topics, one message cut short, one without angular velocity, recorded out of stamp
// order: the chosen topic's samples in stamp order, the two skipped and counted.
TEST(Ros2BagImu, ReadsTheChosenTopicInStampOrderAndCountsWhatItSkips) {
  elo::test::TempDirectory directory;
  const std::string bag = directory.file("imu_bag");
  {
    elo::test::Ros2BagWriter writer(bag);
    writer.addTopic("/points");
    const int64_t imu = writer.addTopic("/imu", elo::kRos2ImuType);
    const int64_t other = writer.addTopic("/imu/other", elo::kRos2ImuType);
    for (const int k : {0, 2, 1, 3}) {
      elo::ImuSample sample;
      sample.angular_velocity = {0.0, 0.0, 0.1 * k};
      writer.write(imu, k, elo::test::encodeCdrImu(sample, {10, static_cast<uint32_t>(k * 5000000)}, k == 3));
    }
    std::vector<uint8_t> cut = elo::test::encodeCdrImu({}, {10, 20000000});
    cut.resize(cut.size() - 1);
    writer.write(imu, 4, cut);
    writer.write(imu, 5, elo::test::encodeCdrImu({}, {10, 25000000}, false, -1.0));
    writer.write(other, 0, elo::test::encodeCdrImu({}, {10, 0}));
  }
  std::string warning;
  const elo::BagImu read = elo::readRos2BagImu(bag, "/imu", warning);
  EXPECT_TRUE(warning.empty()) << warning;
  ASSERT_EQ(read.samples.size(), 4u);
  for (int k = 0; k < 4; ++k) {
    EXPECT_EQ(read.samples[k].stamp, elo::stampSeconds(10, k * 5000000)) << k;
    EXPECT_EQ(read.samples[k].angular_velocity.z(), 0.1 * k) << k;
  }
  EXPECT_EQ(read.skipped.at(elo::imu_message::kUnreadable), 1u);
  EXPECT_EQ(read.skipped.at(elo::imu_message::kNoAngularVelocity), 1u);
  EXPECT_TRUE(contains(read.unreadable_detail, "topic /imu, message 5 of '")) << read.unreadable_detail;
  EXPECT_TRUE(contains(read.unreadable_detail, "malformed CDR Imu")) << read.unreadable_detail;

  const std::string several = errorOf([&] { elo::readRos2BagImu(bag, "", warning); });
  EXPECT_TRUE(contains(several, "several sensor_msgs/msg/Imu topics: /imu (sensor_msgs/msg/Imu, 6 messages), "
                                "/imu/other (sensor_msgs/msg/Imu, 1 messages); choose one with --imu-topic"))
      << several;
  EXPECT_TRUE(contains(errorOf([&] { elo::readRos2BagImu(bag, "/points", warning); }),
                       "has no sensor_msgs/msg/Imu topic /points"));
}

TEST(Ros2BagImu, ABagWithoutImuTopicGivesNone) {
  elo::test::TempDirectory directory;
  const std::string bag = directory.file("clouds_only");
  {
    elo::test::Ros2BagWriter writer(bag);
    writer.addTopic("/points");
  }
  std::string warning;
  EXPECT_TRUE(elo::readRos2BagImu(bag, "", warning).topic.empty());
}

}  // namespace
