// A PointCloud2 message without ROS, and its conversion to elo::PointCloud. ROS 1's sensor_msgs/PointCloud2
// and ROS 2's sensor_msgs/msg/PointCloud2 are the same message, so the nodelet (ROS 1 messages), elo_run's
// ROS 1 bag reader and its ROS 2 bag reader (CDR) all describe what they received as a PointCloud2View and
// convert it here: one conversion, one set of driver conventions. Drivers differ in every detail of the
// message (layout, point types, optional fields, byte order), so the conversion reads fields by name and
// type rather than assuming one driver's struct, and says in words why a cloud it cannot use was rejected.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "elo/types.hpp"

namespace elo {

// PointField datatypes, numbered as the message numbers them (the same in ROS 1 and ROS 2).
namespace point_field {
constexpr uint8_t kInt8 = 1;
constexpr uint8_t kUint8 = 2;
constexpr uint8_t kInt16 = 3;
constexpr uint8_t kUint16 = 4;
constexpr uint8_t kInt32 = 5;
constexpr uint8_t kUint32 = 6;
constexpr uint8_t kFloat32 = 7;
constexpr uint8_t kFloat64 = 8;
}  // namespace point_field

struct CloudField {
  std::string name;
  uint32_t offset = 0;
  uint8_t datatype = 0;
  uint32_t count = 1;
};

// What a PointCloud2 says about its points, and its point bytes, borrowed from the message (not copied):
// the message must outlive the view.
struct PointCloud2View {
  double stamp = 0.0;  // the header stamp, s
  uint32_t height = 0;
  uint32_t width = 0;
  std::vector<CloudField> fields;
  bool is_bigendian = false;
  uint32_t point_step = 0;
  uint32_t row_step = 0;
  const uint8_t* data = nullptr;
  size_t data_size = 0;
};

// A header stamp in seconds, computed as ros::Time::toSec() computes it, so that a ROS 2 stamp gives the
// very double a ROS 1 stamp of the same instant gives.
inline double stampSeconds(int64_t seconds, uint32_t nanoseconds) {
  return static_cast<double>(seconds) + 1e-9 * static_cast<double>(nanoseconds);
}

// Why a cloud cannot be used; the kinds group the counts in the diagnostics and in elo_run's summary.
enum class CloudProblem {
  none,
  no_points,            // width x height is 0
  missing_field,        // no x, y or z
  wrong_type,           // x/y/z not floating point, ring not an integer, or an unknown datatype
  field_outside_point,  // a field's bytes reach past point_step
  truncated,            // data shorter than the header promises
  no_finite_points,     // every point has a NaN or infinite coordinate
};

const char* describe(CloudProblem problem);

struct ConvertedCloud {
  PointCloud cloud;
  // Points dropped for a non-finite coordinate: organized clouds (is_dense false) mark missing returns
  // with NaN, and the core must never see them. elo::readPcd drops the same points.
  size_t non_finite_points = 0;
  CloudProblem problem = CloudProblem::none;
  std::string detail;  // the problem in words, naming the field or the sizes; empty when usable
  // Why the cloud's per-point time field was not read (its type cannot hold a sweep's times); the cloud
  // is still usable, without times. Empty when there is no time field or it was read.
  std::string time_problem;

  bool usable() const { return problem == CloudProblem::none; }
};

// Reads x, y, z (float32 or float64) and, when present, `intensity` (any numeric type), `ring` (any
// integer type) and the per-point times of the first of these fields the cloud has, as
// elo::PointCloud::time (seconds relative to the header stamp):
//   `time`        float32/float64 s relative to the header stamp (velodyne_pointcloud)
//   `t`           uint32/int32 ns from the header stamp (ouster-ros)
//   `timestamp`   float64 absolute s (Hesai's ROS drivers, RoboSense's rslidar_sdk)
//   `time_stamp`  uint32 ns from the header stamp (tier4's nebula), or float64 absolute s
// Any point_step, row padding, organized or not, either byte order, unaligned fields. The stamp is the
// header's.
ConvertedCloud convertPointCloud2(const PointCloud2View& message);

// The byte order messages written on this machine declare.
bool hostIsBigEndian();

}  // namespace elo
