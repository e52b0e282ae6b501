// PointCloud2 clouds laid out byte for byte as the common ROS drivers publish them, each read by the one
// conversion (elo::convertPointCloud2) and its per-point times accepted by the field deskew
// (elo::inspectTimes) as the sweep they are:
//   velodyne_pointcloud  PointXYZIRT: x y z _ intensity ring time (float32 s, relative to the stamp)
//   ouster-ros           x y z _ intensity t reflectivity ring ambient range, padded to 48 bytes (t: uint32 ns)
//   HesaiLidar_ROS_2.0   PointXYZIT: x y z _ intensity timestamp ring (timestamp: float64 absolute s)
//   nebula (Hesai)       PointXYZIRCAEDT: x y z intensity return_type channel azimuth elevation distance
//                        time_stamp (uint32 ns relative to the stamp)
//   rslidar_sdk          XYZIRT as its toRosMsg packs it: x y z intensity ring timestamp, no padding, so
//                        the float64 timestamp sits at byte 18 (absolute s)
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <functional>

#include "elo/config.hpp"
#include "elo/pipeline/deskew.hpp"
#include "elo/io/point_cloud2.hpp"

namespace {

using namespace elo::point_field;

constexpr double kSweep = 0.1;                 // s: a 10 Hz sensor
constexpr double kSweepStart = 1700000000.25;  // an absolute time, as drivers stamp with the system clock
constexpr size_t kPoints = 2000;
constexpr int kRings = 32;

// One point of the sweep: where, which ring, and when (s from the sweep's start).
struct SweepPoint {
  float x, y, z, intensity;
  uint16_t ring;
  double time;
};

std::vector<SweepPoint> sweep() {
  std::vector<SweepPoint> points;
  for (size_t i = 0; i < kPoints; ++i) {
    const double time = kSweep * static_cast<double>(i) / kPoints;
    const double azimuth = 2.0 * M_PI * time / kSweep;
    const uint16_t ring = static_cast<uint16_t>(i % kRings);
    const double range = 5.0 + 20.0 * static_cast<double>(i % 7) / 7.0;
    points.push_back({static_cast<float>(range * std::cos(azimuth)), static_cast<float>(range * std::sin(azimuth)),
                      static_cast<float>(-1.0 + 0.05 * ring), static_cast<float>(i % 255), ring, time});
  }
  return points;
}

// A driver's layout: its fields, its point size, where it puts the header stamp in the sweep, and how it
// writes one point.
struct DriverLayout {
  const char* driver;
  std::vector<elo::CloudField> fields;
  uint32_t point_step;
  double stamp;  // the header stamp
  std::function<void(uint8_t* point, const SweepPoint& p, double stamp)> write;
  bool has_ring;
};

template <typename T>
void put(uint8_t* point, uint32_t offset, T value) {
  std::memcpy(point + offset, &value, sizeof(T));
}

void putXyz(uint8_t* point, const SweepPoint& p) {
  put(point, 0, p.x);
  put(point, 4, p.y);
  put(point, 8, p.z);
}

std::vector<DriverLayout> driverLayouts() {
  const double end = kSweepStart + kSweep;
  return {
      {"velodyne_pointcloud",
       {{"x", 0, kFloat32, 1}, {"y", 4, kFloat32, 1}, {"z", 8, kFloat32, 1}, {"intensity", 16, kFloat32, 1},
        {"ring", 20, kUint16, 1}, {"time", 24, kFloat32, 1}},
       32, end,
       [](uint8_t* point, const SweepPoint& p, double stamp) {
         putXyz(point, p);
         put(point, 16, p.intensity);
         put(point, 20, p.ring);
         put(point, 24, static_cast<float>(kSweepStart + p.time - stamp));
       },
       true},
      {"ouster-ros",
       {{"x", 0, kFloat32, 1}, {"y", 4, kFloat32, 1}, {"z", 8, kFloat32, 1}, {"intensity", 16, kFloat32, 1},
        {"t", 20, kUint32, 1}, {"reflectivity", 24, kUint16, 1}, {"ring", 26, kUint16, 1},
        {"ambient", 28, kUint16, 1}, {"range", 32, kUint32, 1}},
       48, kSweepStart,
       [](uint8_t* point, const SweepPoint& p, double) {
         putXyz(point, p);
         put(point, 16, p.intensity);
         put(point, 20, static_cast<uint32_t>(std::llround(p.time * 1e9)));
         put(point, 24, static_cast<uint16_t>(7));
         put(point, 26, p.ring);
         put(point, 28, static_cast<uint16_t>(300));
         put(point, 32, static_cast<uint32_t>(12000));
       },
       true},
      {"HesaiLidar_ROS_2.0",
       {{"x", 0, kFloat32, 1}, {"y", 4, kFloat32, 1}, {"z", 8, kFloat32, 1}, {"intensity", 16, kFloat32, 1},
        {"timestamp", 24, kFloat64, 1}, {"ring", 32, kUint16, 1}},
       48, kSweepStart,
       [](uint8_t* point, const SweepPoint& p, double) {
         putXyz(point, p);
         put(point, 16, p.intensity);
         put(point, 24, kSweepStart + p.time);
         put(point, 32, p.ring);
       },
       true},
      {"nebula",
       {{"x", 0, kFloat32, 1}, {"y", 4, kFloat32, 1}, {"z", 8, kFloat32, 1}, {"intensity", 12, kUint8, 1},
        {"return_type", 13, kUint8, 1}, {"channel", 14, kUint16, 1}, {"azimuth", 16, kFloat32, 1},
        {"elevation", 20, kFloat32, 1}, {"distance", 24, kFloat32, 1}, {"time_stamp", 28, kUint32, 1}},
       32, kSweepStart,
       [](uint8_t* point, const SweepPoint& p, double) {
         putXyz(point, p);
         put(point, 12, static_cast<uint8_t>(p.intensity));
         put(point, 13, static_cast<uint8_t>(1));
         put(point, 14, p.ring);
         put(point, 16, static_cast<float>(std::atan2(p.y, p.x)));
         put(point, 20, 0.0f);
         put(point, 24, std::hypot(p.x, p.y));
         put(point, 28, static_cast<uint32_t>(std::llround(p.time * 1e9)));
       },
       false},  // `channel` is the laser's id, not a ring the conversion reads
      {"rslidar_sdk",
       {{"x", 0, kFloat32, 1}, {"y", 4, kFloat32, 1}, {"z", 8, kFloat32, 1}, {"intensity", 12, kFloat32, 1},
        {"ring", 16, kUint16, 1}, {"timestamp", 18, kFloat64, 1}},
       26, end,
       [](uint8_t* point, const SweepPoint& p, double) {
         putXyz(point, p);
         put(point, 12, p.intensity);
         put(point, 16, p.ring);
         put(point, 18, kSweepStart + p.time);
       },
       true},
  };
}

// One row of the driver's points, as its message describes them.
elo::PointCloud2View viewOf(const DriverLayout& layout, const std::vector<uint8_t>& data, bool big_endian) {
  elo::PointCloud2View view;
  view.stamp = layout.stamp;
  view.height = 1;
  view.width = static_cast<uint32_t>(data.size() / layout.point_step);
  view.fields = layout.fields;
  view.is_bigendian = big_endian;
  view.point_step = layout.point_step;
  view.row_step = layout.point_step * view.width;
  view.data = data.data();
  view.data_size = data.size();
  return view;
}

TEST(DriverLayouts, EachDriversCloudIsReadWithItsTimesAndRings) {
  const std::vector<SweepPoint> points = sweep();
  elo::Config config;
  config.deskew.time_source = elo::TimeSource::field;
  for (const DriverLayout& layout : driverLayouts()) {
    SCOPED_TRACE(layout.driver);
    std::vector<uint8_t> data(static_cast<size_t>(layout.point_step) * points.size(), 0xAB);  // padding is garbage
    for (size_t i = 0; i < points.size(); ++i) layout.write(data.data() + i * layout.point_step, points[i], layout.stamp);
    const elo::ConvertedCloud converted = elo::convertPointCloud2(viewOf(layout, data, elo::hostIsBigEndian()));
    ASSERT_TRUE(converted.usable()) << converted.detail;
    EXPECT_TRUE(converted.time_problem.empty()) << converted.time_problem;
    const elo::PointCloud& cloud = converted.cloud;
    ASSERT_EQ(cloud.size(), points.size());
    ASSERT_EQ(cloud.time.size(), points.size());
    EXPECT_EQ(cloud.ring.size(), layout.has_ring ? points.size() : 0u);
    EXPECT_EQ(cloud.stamp, layout.stamp);
    double largest_time_error = 0.0;
    for (size_t i = 0; i < points.size(); ++i) {
      EXPECT_EQ(cloud.points[i], elo::Vec3f(points[i].x, points[i].y, points[i].z));
      if (layout.has_ring) {
        EXPECT_EQ(cloud.ring[i], points[i].ring);
      }
      const double expected = kSweepStart + points[i].time - layout.stamp;
      largest_time_error = std::max(largest_time_error, std::abs(cloud.time[i] - expected));
    }
    // Absolute float64 seconds near 1.7e9 s hold about 0.24 us; float32 relative times about 4 ns.
    EXPECT_LT(largest_time_error, 1e-6);

    const elo::CloudTimes times = elo::inspectTimes(cloud, config);
    EXPECT_EQ(times.source, elo::TimeSource::field) << times.warning;
    EXPECT_TRUE(times.warning.empty()) << times.warning;
    EXPECT_EQ(times.outside_sweep, 0u);
    // The reference instant is mid-sweep, whichever end the driver stamps.
    EXPECT_NEAR(layout.stamp + times.reference, kSweepStart + 0.5 * kSweep * (kPoints - 1) / kPoints, 1e-6);
    EXPECT_NEAR(times.farthest, 0.5 * kSweep * (kPoints - 1) / kPoints, 1e-6);
  }
}

// The same clouds written in the other byte order, as a big-endian host's driver sends them.
TEST(DriverLayouts, ReadsTheTimesOfAnotherByteOrder) {
  const std::vector<SweepPoint> points = sweep();
  for (const DriverLayout& layout : driverLayouts()) {
    SCOPED_TRACE(layout.driver);
    std::vector<uint8_t> data(static_cast<size_t>(layout.point_step) * points.size(), 0);
    for (size_t i = 0; i < points.size(); ++i) {
      uint8_t* point = data.data() + i * layout.point_step;
      layout.write(point, points[i], layout.stamp);
      for (const elo::CloudField& field : layout.fields) {
        const size_t size = field.datatype == kFloat64 ? 8 : field.datatype >= kInt32 ? 4 : field.datatype >= kInt16 ? 2 : 1;
        std::reverse(point + field.offset, point + field.offset + size);
      }
    }
    const elo::ConvertedCloud converted = elo::convertPointCloud2(viewOf(layout, data, !elo::hostIsBigEndian()));
    ASSERT_TRUE(converted.usable()) << converted.detail;
    ASSERT_EQ(converted.cloud.time.size(), points.size());
    EXPECT_NEAR(converted.cloud.time.back(), kSweepStart + points.back().time - layout.stamp, 1e-6);
    EXPECT_EQ(converted.cloud.points.back(), elo::Vec3f(points.back().x, points.back().y, points.back().z));
  }
}

}  // namespace
