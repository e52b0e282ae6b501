// PointCloud2 -> elo::PointCloud as real drivers publish them: layouts, types, optional fields, byte
// order, and every reason a cloud is rejected. No ROS master needed.
#include <gtest/gtest.h>
#include <sensor_msgs/PointField.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>

#include "cloud_conversion.hpp"

namespace {

using elo_ros::CloudProblem;
using sensor_msgs::PointField;

struct FieldSpec {
  std::string name;
  uint32_t offset;
  uint8_t datatype;
};

// A message with the given fields and an empty (zeroed) body of width x height points.
sensor_msgs::PointCloud2 makeMessage(const std::vector<FieldSpec>& fields, uint32_t point_step, uint32_t width,
                                     uint32_t height = 1, uint32_t row_padding = 0) {
  sensor_msgs::PointCloud2 message;
  message.header.stamp = ros::Time(1234, 500000000);
  message.header.frame_id = "lidar";
  for (const FieldSpec& spec : fields) {
    PointField field;
    field.name = spec.name;
    field.offset = spec.offset;
    field.datatype = spec.datatype;
    field.count = 1;
    message.fields.push_back(field);
  }
  message.point_step = point_step;
  message.width = width;
  message.height = height;
  message.row_step = point_step * width + row_padding;
  message.is_bigendian = elo::hostIsBigEndian();
  message.data.assign(static_cast<size_t>(message.row_step) * height, 0);
  return message;
}

uint8_t* pointAt(sensor_msgs::PointCloud2& message, uint32_t row, uint32_t column) {
  return message.data.data() + row * message.row_step + column * message.point_step;
}

template <typename T>
void put(uint8_t* point, uint32_t offset, T value) {
  std::memcpy(point + offset, &value, sizeof(T));
}

const std::vector<FieldSpec> kXyzFloat = {
    {"x", 0, PointField::FLOAT32}, {"y", 4, PointField::FLOAT32}, {"z", 8, PointField::FLOAT32}};

TEST(CloudConversion, RoundTripsWhatToPointCloud2Writes) {
  elo::PointCloud cloud;
  cloud.points = {{1.0f, 2.0f, 3.0f}, {-4.5f, 0.25f, 7.0f}};
  cloud.intensity = {10.0f, 20.0f};
  cloud.ring = {3, 63};
  cloud.time = {0.0f, 0.0999f};
  cloud.stamp = 1234.5;
  const sensor_msgs::PointCloud2 message = elo_ros::toPointCloud2(cloud, "lidar");

  const elo_ros::ConvertedCloud converted = elo_ros::fromPointCloud2(message);
  ASSERT_TRUE(converted.usable()) << converted.detail;
  EXPECT_EQ(converted.cloud.points, cloud.points);
  EXPECT_EQ(converted.cloud.intensity, cloud.intensity);
  EXPECT_EQ(converted.cloud.ring, cloud.ring);
  EXPECT_EQ(converted.cloud.time, cloud.time);
  EXPECT_DOUBLE_EQ(converted.cloud.stamp, 1234.5);
  EXPECT_EQ(message.header.frame_id, "lidar");
}

TEST(CloudConversion, WritesNaturallyAlignedFields) {
  elo::PointCloud cloud;
  cloud.points = {{1.0f, 2.0f, 3.0f}};
  cloud.intensity = {1.0f};
  cloud.ring = {5};
  cloud.time = {0.05f};
  const sensor_msgs::PointCloud2 message = elo_ros::toPointCloud2(cloud, "lidar");
  ASSERT_EQ(message.fields.size(), 6u);
  EXPECT_EQ(message.fields[4].name, "ring");
  EXPECT_EQ(message.fields[4].offset, 16u);
  EXPECT_EQ(message.fields[5].name, "time");
  EXPECT_EQ(message.fields[5].offset, 20u);
  EXPECT_EQ(message.point_step, 24u);
  EXPECT_TRUE(message.is_dense);

  elo::PointCloud bare;
  bare.points = {{1.0f, 2.0f, 3.0f}};
  EXPECT_EQ(elo_ros::toPointCloud2(bare, "lidar").fields.size(), 3u) << "optional fields only when present";
}

TEST(CloudConversion, OrganizedCloudDropsNaNsAndHonoursRowPadding) {
  sensor_msgs::PointCloud2 message = makeMessage(kXyzFloat, 16, 3, 2, 8);
  message.is_dense = false;
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const float values[2][3][3] = {{{1, 2, 3}, {nan, nan, nan}, {4, 5, 6}},
                                 {{7, 8, 9}, {10, 11, 12}, {nan, 0, 0}}};
  for (uint32_t row = 0; row < 2; ++row) {
    for (uint32_t column = 0; column < 3; ++column) {
      for (uint32_t axis = 0; axis < 3; ++axis) put(pointAt(message, row, column), axis * 4, values[row][column][axis]);
    }
  }
  const elo_ros::ConvertedCloud converted = elo_ros::fromPointCloud2(message);
  ASSERT_TRUE(converted.usable()) << converted.detail;
  EXPECT_EQ(converted.non_finite_points, 2u);
  const std::vector<elo::Vec3f> expected = {{1, 2, 3}, {4, 5, 6}, {7, 8, 9}, {10, 11, 12}};
  EXPECT_EQ(converted.cloud.points, expected);
  EXPECT_TRUE(converted.cloud.intensity.empty());
  EXPECT_TRUE(converted.cloud.ring.empty());
  EXPECT_TRUE(converted.cloud.time.empty());
}

// The layout of the Ouster driver's PointXYZIRT-like point: extra fields, integer nanosecond `t`, a
// uint8 ring, and a point_step larger than the fields need.
TEST(CloudConversion, OusterLayoutReadsNanosecondTimesAndRing) {
  const std::vector<FieldSpec> fields = {{"x", 0, PointField::FLOAT32},         {"y", 4, PointField::FLOAT32},
                                         {"z", 8, PointField::FLOAT32},         {"intensity", 16, PointField::FLOAT32},
                                         {"t", 20, PointField::UINT32},         {"reflectivity", 24, PointField::UINT16},
                                         {"ring", 26, PointField::UINT8},       {"ambient", 28, PointField::UINT16},
                                         {"range", 32, PointField::UINT32}};
  sensor_msgs::PointCloud2 message = makeMessage(fields, 48, 2);
  for (uint32_t i = 0; i < 2; ++i) {
    uint8_t* point = pointAt(message, 0, i);
    put(point, 0, 1.0f + i);
    put(point, 4, 2.0f);
    put(point, 8, 3.0f);
    put(point, 16, 100.0f * (i + 1));
    put(point, 20, static_cast<uint32_t>(50000000u * i));  // 0 and 50 ms
    put(point, 26, static_cast<uint8_t>(i + 7));
  }
  const elo_ros::ConvertedCloud converted = elo_ros::fromPointCloud2(message);
  ASSERT_TRUE(converted.usable()) << converted.detail;
  EXPECT_EQ(converted.cloud.points[1], elo::Vec3f(2, 2, 3));
  EXPECT_EQ(converted.cloud.intensity, (std::vector<float>{100.0f, 200.0f}));
  EXPECT_EQ(converted.cloud.ring, (std::vector<uint16_t>{7, 8}));
  ASSERT_EQ(converted.cloud.time.size(), 2u);
  EXPECT_FLOAT_EQ(converted.cloud.time[1], 0.05f);
}

// Velodyne's driver: float seconds in `time`, uint16 ring; `time` wins over `t` when both exist.
TEST(CloudConversion, FloatTimeInSecondsPreferredOverT) {
  const std::vector<FieldSpec> fields = {{"x", 0, PointField::FLOAT32}, {"y", 4, PointField::FLOAT32},
                                         {"z", 8, PointField::FLOAT32}, {"ring", 12, PointField::UINT16},
                                         {"time", 16, PointField::FLOAT32}, {"t", 20, PointField::UINT32}};
  sensor_msgs::PointCloud2 message = makeMessage(fields, 24, 1);
  put(pointAt(message, 0, 0), 0, 5.0f);
  put(pointAt(message, 0, 0), 12, static_cast<uint16_t>(42));
  put(pointAt(message, 0, 0), 16, 0.025f);
  put(pointAt(message, 0, 0), 20, static_cast<uint32_t>(99));
  const elo_ros::ConvertedCloud converted = elo_ros::fromPointCloud2(message);
  ASSERT_TRUE(converted.usable()) << converted.detail;
  EXPECT_EQ(converted.cloud.ring, (std::vector<uint16_t>{42}));
  EXPECT_EQ(converted.cloud.time, (std::vector<float>{0.025f}));
}

// Velodyne stamps a sweep at its last packet: times are negative, relative to the header stamp, and stay so.
TEST(CloudConversion, VelodyneTimesStayRelativeToTheStamp) {
  std::vector<FieldSpec> fields = kXyzFloat;
  fields.push_back({"time", 12, PointField::FLOAT32});
  sensor_msgs::PointCloud2 message = makeMessage(fields, 16, 2);
  put(pointAt(message, 0, 0), 12, -0.0999f);
  put(pointAt(message, 0, 1), 12, -0.0001f);
  const elo_ros::ConvertedCloud converted = elo_ros::fromPointCloud2(message);
  ASSERT_TRUE(converted.usable()) << converted.detail;
  EXPECT_EQ(converted.cloud.time, (std::vector<float>{-0.0999f, -0.0001f}));
  EXPECT_TRUE(converted.time_problem.empty());
}

// Hesai (and RoboSense) write absolute float64 seconds: the header stamp is subtracted.
TEST(CloudConversion, AbsoluteTimestampsBecomeRelativeToTheStamp) {
  std::vector<FieldSpec> fields = kXyzFloat;
  fields.push_back({"timestamp", 16, PointField::FLOAT64});
  sensor_msgs::PointCloud2 message = makeMessage(fields, 24, 2);
  const double stamp = message.header.stamp.toSec();  // 1234.5
  put(pointAt(message, 0, 0), 16, stamp - 0.1);
  put(pointAt(message, 0, 1), 16, stamp + 0.025);
  const elo_ros::ConvertedCloud converted = elo_ros::fromPointCloud2(message);
  ASSERT_TRUE(converted.usable()) << converted.detail;
  ASSERT_EQ(converted.cloud.time.size(), 2u);
  EXPECT_NEAR(converted.cloud.time[0], -0.1f, 1e-9f);
  EXPECT_NEAR(converted.cloud.time[1], 0.025f, 1e-9f);
}

// A time field whose type cannot hold a sweep's times loses the times, not the cloud, and says why.
TEST(CloudConversion, ATimeFieldOfTheWrongTypeIsLeftOutWithTheReason) {
  const std::pair<const char*, uint8_t> wrong[] = {
      {"time", PointField::UINT16}, {"t", PointField::UINT16}, {"t", PointField::FLOAT32},
      {"timestamp", PointField::FLOAT32}};
  for (const auto& [name, datatype] : wrong) {
    std::vector<FieldSpec> fields = kXyzFloat;
    fields.push_back({name, 12, datatype});
    const elo_ros::ConvertedCloud converted = elo_ros::fromPointCloud2(makeMessage(fields, 16, 3));
    ASSERT_TRUE(converted.usable()) << name << ": " << converted.detail;
    EXPECT_EQ(converted.cloud.size(), 3u);
    EXPECT_TRUE(converted.cloud.time.empty()) << name;
    EXPECT_NE(converted.time_problem.find(std::string("'") + name + "'"), std::string::npos) << converted.time_problem;
    EXPECT_NE(converted.time_problem.find("without per-point times"), std::string::npos) << converted.time_problem;
  }
}

TEST(CloudConversion, ReadsFloat64Coordinates) {
  const std::vector<FieldSpec> fields = {
      {"x", 0, PointField::FLOAT64}, {"y", 8, PointField::FLOAT64}, {"z", 16, PointField::FLOAT64},
      {"intensity", 24, PointField::UINT8}};
  sensor_msgs::PointCloud2 message = makeMessage(fields, 32, 2);
  put(pointAt(message, 0, 0), 0, 1.5);
  put(pointAt(message, 0, 0), 8, -2.25);
  put(pointAt(message, 0, 0), 16, 1e300);  // beyond float: not finite once stored as the core stores it
  put(pointAt(message, 0, 1), 0, 0.1);
  put(pointAt(message, 0, 1), 8, 0.2);
  put(pointAt(message, 0, 1), 16, 0.3);
  put(pointAt(message, 0, 1), 24, static_cast<uint8_t>(200));
  const elo_ros::ConvertedCloud converted = elo_ros::fromPointCloud2(message);
  ASSERT_TRUE(converted.usable()) << converted.detail;
  EXPECT_EQ(converted.non_finite_points, 1u);
  ASSERT_EQ(converted.cloud.size(), 1u);
  EXPECT_EQ(converted.cloud.points[0], elo::Vec3f(0.1f, 0.2f, 0.3f));
  EXPECT_EQ(converted.cloud.intensity, (std::vector<float>{200.0f}));
}

// A driver that sends no intensity (or one configured without it): the field is optional.
TEST(CloudConversion, MissingIntensityIsOptional) {
  const std::vector<FieldSpec> fields = {{"x", 0, PointField::FLOAT32}, {"y", 4, PointField::FLOAT32},
                                         {"z", 8, PointField::FLOAT32}, {"ring", 12, PointField::UINT16},
                                         {"time", 16, PointField::FLOAT32}};
  sensor_msgs::PointCloud2 message = makeMessage(fields, 20, 2);
  for (uint32_t i = 0; i < 2; ++i) {
    put(pointAt(message, 0, i), 0, 3.0f + i);
    put(pointAt(message, 0, i), 12, static_cast<uint16_t>(i));
    put(pointAt(message, 0, i), 16, 0.01f * i);
  }
  const elo_ros::ConvertedCloud converted = elo_ros::fromPointCloud2(message);
  ASSERT_TRUE(converted.usable()) << converted.detail;
  EXPECT_EQ(converted.cloud.size(), 2u);
  EXPECT_TRUE(converted.cloud.intensity.empty());
  EXPECT_EQ(converted.cloud.ring, (std::vector<uint16_t>{0, 1}));
  EXPECT_EQ(converted.cloud.time, (std::vector<float>{0.0f, 0.01f}));
}

// A driver sending a single laser's packets: one organized row, every point on the same ring. The
// conversion keeps them all; what the odometry makes of them is test/core's FaultCases.
TEST(CloudConversion, OneRingCloudKeepsEveryPointOnItsRing) {
  std::vector<FieldSpec> fields = kXyzFloat;
  fields.push_back({"ring", 12, PointField::UINT16});
  sensor_msgs::PointCloud2 message = makeMessage(fields, 16, 1800, 1);
  for (uint32_t i = 0; i < message.width; ++i) {
    const float azimuth = 2.0f * static_cast<float>(M_PI) * i / message.width;
    put(pointAt(message, 0, i), 0, 10.0f * std::cos(azimuth));
    put(pointAt(message, 0, i), 4, 10.0f * std::sin(azimuth));
    put(pointAt(message, 0, i), 8, -1.73f);
    put(pointAt(message, 0, i), 12, static_cast<uint16_t>(40));
  }
  const elo_ros::ConvertedCloud converted = elo_ros::fromPointCloud2(message);
  ASSERT_TRUE(converted.usable()) << converted.detail;
  EXPECT_EQ(converted.cloud.size(), 1800u);
  EXPECT_TRUE(std::all_of(converted.cloud.ring.begin(), converted.cloud.ring.end(), [](uint16_t r) { return r == 40; }));
}

// Two million points (an aggregated or dual-return cloud, 16 times an HDL-64E sweep) convert in one
// linear pass; the bound is loose for a loaded machine, the measured time is ~0.1 s.
TEST(CloudConversion, TwoMillionPointCloudConvertsInBoundedTime) {
  elo::PointCloud cloud;
  constexpr size_t kPoints = 2000000;
  cloud.points.reserve(kPoints);
  for (size_t i = 0; i < kPoints; ++i) {
    const float azimuth = 2.0f * static_cast<float>(M_PI) * (i % 2048) / 2048.0f;
    cloud.points.emplace_back(20.0f * std::cos(azimuth), 20.0f * std::sin(azimuth), 0.001f * (i % 1000));
  }
  cloud.intensity.assign(kPoints, 1.0f);
  cloud.ring.assign(kPoints, 3);
  cloud.stamp = 100.0;
  const sensor_msgs::PointCloud2 message = elo_ros::toPointCloud2(cloud, "lidar");
  const auto start = std::chrono::steady_clock::now();
  const elo_ros::ConvertedCloud converted = elo_ros::fromPointCloud2(message);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  ASSERT_TRUE(converted.usable()) << converted.detail;
  EXPECT_EQ(converted.cloud.size(), kPoints);
  EXPECT_EQ(converted.cloud.points.back(), cloud.points.back());
  EXPECT_LT(seconds, 3.0);
  std::printf("2,000,000 points converted in %.3f s\n", seconds);
}

// The same values written in the other byte order, with is_bigendian saying so.
TEST(CloudConversion, SwapsBytesOfTheOtherByteOrder) {
  const std::vector<FieldSpec> fields = {{"x", 0, PointField::FLOAT32}, {"y", 4, PointField::FLOAT32},
                                         {"z", 8, PointField::FLOAT32}, {"ring", 12, PointField::UINT16}};
  sensor_msgs::PointCloud2 message = makeMessage(fields, 16, 1);
  put(pointAt(message, 0, 0), 0, 1.25f);
  put(pointAt(message, 0, 0), 4, -3.5f);
  put(pointAt(message, 0, 0), 8, 1000.0f);
  put(pointAt(message, 0, 0), 12, static_cast<uint16_t>(0x0102));
  for (const uint32_t offset : {0u, 4u, 8u}) std::reverse(pointAt(message, 0, 0) + offset, pointAt(message, 0, 0) + offset + 4);
  std::reverse(pointAt(message, 0, 0) + 12, pointAt(message, 0, 0) + 14);
  message.is_bigendian = !elo::hostIsBigEndian();

  const elo_ros::ConvertedCloud converted = elo_ros::fromPointCloud2(message);
  ASSERT_TRUE(converted.usable()) << converted.detail;
  EXPECT_EQ(converted.cloud.points[0], elo::Vec3f(1.25f, -3.5f, 1000.0f));
  EXPECT_EQ(converted.cloud.ring, (std::vector<uint16_t>{0x0102}));
}

void expectRejected(const sensor_msgs::PointCloud2& message, CloudProblem problem, const std::string& naming) {
  const elo_ros::ConvertedCloud converted = elo_ros::fromPointCloud2(message);
  EXPECT_FALSE(converted.usable());
  EXPECT_EQ(converted.problem, problem) << converted.detail;
  EXPECT_NE(converted.detail.find(naming), std::string::npos) << "'" << converted.detail << "' should name '" << naming << "'";
  EXPECT_TRUE(converted.cloud.points.empty());
  EXPECT_STRNE(elo::describe(problem), "usable");
}

TEST(CloudConversion, RejectsACloudWithoutCoordinates) {
  expectRejected(makeMessage({{"x", 0, PointField::FLOAT32}, {"y", 4, PointField::FLOAT32}}, 12, 4),
                 CloudProblem::missing_field, "'z'");
}

TEST(CloudConversion, RejectsIntegerCoordinates) {
  expectRejected(makeMessage({{"x", 0, PointField::INT16}, {"y", 2, PointField::INT16}, {"z", 4, PointField::INT16}},
                             6, 4),
                 CloudProblem::wrong_type, "int16");
}

TEST(CloudConversion, RejectsAFloatingPointRing) {
  std::vector<FieldSpec> fields = kXyzFloat;
  fields.push_back({"ring", 12, PointField::FLOAT32});
  expectRejected(makeMessage(fields, 16, 4), CloudProblem::wrong_type, "ring");
}

TEST(CloudConversion, RejectsAnUnknownDatatype) {
  std::vector<FieldSpec> fields = kXyzFloat;
  fields.push_back({"intensity", 12, 42});
  expectRejected(makeMessage(fields, 16, 4), CloudProblem::wrong_type, "unknown datatype 42");
}

TEST(CloudConversion, RejectsAFieldBeyondThePoint) {
  expectRejected(makeMessage({{"x", 0, PointField::FLOAT32}, {"y", 4, PointField::FLOAT32}, {"z", 8, PointField::FLOAT64}},
                             12, 4),
                 CloudProblem::field_outside_point, "point_step 12");
}

TEST(CloudConversion, RejectsTruncatedData) {
  sensor_msgs::PointCloud2 message = makeMessage(kXyzFloat, 12, 10);
  message.data.resize(message.data.size() - 1);
  expectRejected(message, CloudProblem::truncated, "truncated");

  sensor_msgs::PointCloud2 short_rows = makeMessage(kXyzFloat, 12, 10);
  short_rows.row_step = 100;
  expectRejected(short_rows, CloudProblem::truncated, "row_step 100");
}

TEST(CloudConversion, RejectsAnEmptyCloud) {
  expectRejected(makeMessage(kXyzFloat, 12, 0), CloudProblem::no_points, "no points");
}

TEST(CloudConversion, RejectsACloudOfNaNs) {
  sensor_msgs::PointCloud2 message = makeMessage(kXyzFloat, 12, 3);
  for (uint32_t i = 0; i < 3; ++i) put(pointAt(message, 0, i), 0, std::numeric_limits<float>::quiet_NaN());
  expectRejected(message, CloudProblem::no_finite_points, "all 3");
}

// A ring that uint16 cannot hold was undefined behaviour to convert (found by fuzzing under UBSan); it
// is now the unknown ring, which the projection drops like any other beam it does not know.
TEST(CloudConversion, RingOutsideUint16BecomesTheUnknownRing) {
  std::vector<FieldSpec> fields = kXyzFloat;
  fields.push_back({"ring", 12, PointField::INT32});
  sensor_msgs::PointCloud2 message = makeMessage(fields, 16, 3);
  const int32_t rings[] = {5, -1, 70000};
  for (uint32_t i = 0; i < 3; ++i) {
    put(pointAt(message, 0, i), 0, 10.0f);
    put(pointAt(message, 0, i), 12, rings[i]);
  }
  const elo_ros::ConvertedCloud converted = elo_ros::fromPointCloud2(message);
  ASSERT_TRUE(converted.usable()) << converted.detail;
  EXPECT_EQ(converted.cloud.ring, (std::vector<uint16_t>{5, elo::kUnknownRing, elo::kUnknownRing}));
}

}  // namespace
