// sensor_msgs/PointCloud2 <-> elo::PointCloud. Drivers differ in every detail of the message (layout,
// point types, optional fields, byte order), so the conversion reads fields by name and type rather than
// assuming one driver's struct, and says in words why a cloud it cannot use was rejected.
#pragma once

#include <sensor_msgs/PointCloud2.h>

#include <cstddef>
#include <string>

#include "elo/types.hpp"

namespace elo_ros {

// Why a cloud cannot be used; the kinds group the counts in the diagnostics.
enum class CloudProblem {
  none,
  no_points,         // width x height is 0
  missing_field,     // no x, y or z
  wrong_type,        // x/y/z not floating point, ring not an integer, or an unknown datatype
  field_outside_point,  // a field's bytes reach past point_step
  truncated,         // data shorter than the header promises
  no_finite_points,  // every point has a NaN or infinite coordinate
};

const char* describe(CloudProblem problem);

struct ConvertedCloud {
  elo::PointCloud cloud;
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
// integer type) and the per-point times of the first of `time` (float seconds relative to the header
// stamp, Velodyne), `t` (uint32 nanoseconds from the header stamp, Ouster) and `timestamp` (float64
// absolute seconds, Hesai), as elo::PointCloud::time: seconds relative to the header stamp.
// Any point_step, row padding, organized or not, either byte order. The stamp is the header's.
ConvertedCloud fromPointCloud2(const sensor_msgs::PointCloud2& message);

// Packs a cloud as x y z [intensity] [ring] [time]: float32, ring uint16, each field naturally aligned;
// optional fields only when the cloud has them. The header stamp is the cloud's stamp.
sensor_msgs::PointCloud2 toPointCloud2(const elo::PointCloud& cloud, const std::string& frame_id);

// The byte order messages written on this machine declare.
bool hostIsBigEndian();

}  // namespace elo_ros
