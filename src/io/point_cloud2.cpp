#include "elo/io/point_cloud2.hpp"

#include <algorithm>
#include <cstring>
#include <optional>

namespace elo {
namespace {

size_t datatypeSize(uint8_t datatype) {
  switch (datatype) {
    case point_field::kInt8:
    case point_field::kUint8: return 1;
    case point_field::kInt16:
    case point_field::kUint16: return 2;
    case point_field::kInt32:
    case point_field::kUint32:
    case point_field::kFloat32: return 4;
    case point_field::kFloat64: return 8;
    default: return 0;  // not a PointField type
  }
}

std::string datatypeName(uint8_t datatype) {
  switch (datatype) {
    case point_field::kInt8: return "int8";
    case point_field::kUint8: return "uint8";
    case point_field::kInt16: return "int16";
    case point_field::kUint16: return "uint16";
    case point_field::kInt32: return "int32";
    case point_field::kUint32: return "uint32";
    case point_field::kFloat32: return "float32";
    case point_field::kFloat64: return "float64";
    default: return "unknown datatype " + std::to_string(datatype);
  }
}

bool isFloatingPoint(uint8_t datatype) {
  return datatype == point_field::kFloat32 || datatype == point_field::kFloat64;
}

// Message data need not be aligned, so a value is copied out byte by byte (and reversed when the
// message's byte order is not the host's).
template <typename T>
double readAs(const uint8_t* source, bool swap_bytes) {
  uint8_t bytes[sizeof(T)];
  std::memcpy(bytes, source, sizeof(T));
  if (swap_bytes) std::reverse(bytes, bytes + sizeof(T));
  T value;
  std::memcpy(&value, bytes, sizeof(T));
  return static_cast<double>(value);
}

// One field of the message, checked once so that the per-point loop only reads.
struct FieldReader {
  uint32_t offset = 0;
  uint8_t datatype = 0;
  bool swap_bytes = false;

  double read(const uint8_t* point) const {
    const uint8_t* source = point + offset;
    switch (datatype) {
      case point_field::kInt8: return readAs<int8_t>(source, swap_bytes);
      case point_field::kUint8: return readAs<uint8_t>(source, swap_bytes);
      case point_field::kInt16: return readAs<int16_t>(source, swap_bytes);
      case point_field::kUint16: return readAs<uint16_t>(source, swap_bytes);
      case point_field::kInt32: return readAs<int32_t>(source, swap_bytes);
      case point_field::kUint32: return readAs<uint32_t>(source, swap_bytes);
      case point_field::kFloat32: return readAs<float>(source, swap_bytes);
      default: return readAs<double>(source, swap_bytes);
    }
  }
};

// How a driver's per-point times become PointCloud::time, seconds relative to the header stamp.
struct TimeReader {
  FieldReader field;
  double scale = 1.0;   // seconds per stored unit
  double offset = 0.0;  // subtracted after scaling: the header stamp, for absolute times
};

struct Layout {
  FieldReader x, y, z;
  std::optional<FieldReader> intensity, ring;
  std::optional<TimeReader> time;
  std::string time_problem;  // why a time field present was not read; empty otherwise
};

struct Rejection {
  CloudProblem problem;
  std::string detail;
};

const CloudField* findField(const PointCloud2View& message, const std::string& name) {
  const auto field = std::find_if(message.fields.begin(), message.fields.end(),
                                  [&](const CloudField& f) { return f.name == name; });
  return field == message.fields.end() ? nullptr : &*field;
}

// A field the conversion reads must have a known type and lie inside a point.
std::optional<Rejection> checkField(const CloudField& field, uint32_t point_step) {
  const size_t size = datatypeSize(field.datatype);
  if (size == 0) {
    return Rejection{CloudProblem::wrong_type, "field '" + field.name + "' has " + datatypeName(field.datatype)};
  }
  if (static_cast<size_t>(field.offset) + size > point_step) {
    return Rejection{CloudProblem::field_outside_point,
                     "field '" + field.name + "' (offset " + std::to_string(field.offset) + ", " +
                         std::to_string(size) + " bytes) does not fit in point_step " + std::to_string(point_step)};
  }
  return std::nullopt;
}

// How a time field's stored values become seconds relative to the header stamp.
struct TimeUnit {
  double scale;   // seconds per stored unit
  bool absolute;  // absolute time: the header stamp is subtracted
};

// The drivers' per-point time conventions (docs/deskew.md), in this order of preference:
//   `time`       float32/float64 s relative to the header stamp (velodyne_pointcloud: negative, the stamp
//                ends the sweep)
//   `t`          uint32/int32 ns from the sweep's start, which the header stamp is (ouster-ros)
//   `timestamp`  float64 absolute s (Hesai's ROS drivers, RoboSense's rslidar_sdk)
//   `time_stamp` uint32 ns from the header stamp (nebula's PointXYZIRCAEDT), or float64 absolute s
//                (its older PointXYZIRADT)
// A time field of another type cannot hold a sweep's times (an 8- or 16-bit count of nanoseconds, an
// absolute time in float32, to two minutes): the cloud is read without times and `time_problem` says
// why, so that the scan is still used, as an instantaneous one.
void findTimes(const PointCloud2View& message, bool swap_bytes, Layout& layout) {
  using point_field::kFloat64;
  using point_field::kInt32;
  using point_field::kUint32;
  struct Convention {
    const char* name;
    std::optional<TimeUnit> (*unit)(uint8_t datatype);  // none: the type cannot hold a sweep's times
    const char* expected;
  };
  static const Convention kConventions[] = {
      {"time", [](uint8_t type) { return isFloatingPoint(type) ? std::optional<TimeUnit>({1.0, false}) : std::nullopt; },
       "float32 or float64 seconds relative to the header stamp"},
      {"t",
       [](uint8_t type) {
         return type == kUint32 || type == kInt32 ? std::optional<TimeUnit>({1e-9, false}) : std::nullopt;
       },
       "uint32 nanoseconds from the header stamp"},
      {"timestamp", [](uint8_t type) { return type == kFloat64 ? std::optional<TimeUnit>({1.0, true}) : std::nullopt; },
       "float64 absolute seconds"},
      {"time_stamp",
       [](uint8_t type) -> std::optional<TimeUnit> {
         if (type == kUint32) return TimeUnit{1e-9, false};
         if (type == kFloat64) return TimeUnit{1.0, true};
         return std::nullopt;
       },
       "uint32 nanoseconds from the header stamp or float64 absolute seconds"},
  };
  for (const Convention& convention : kConventions) {
    const CloudField* field = findField(message, convention.name);
    if (field == nullptr) continue;
    const std::optional<TimeUnit> unit = convention.unit(field->datatype);
    if (auto problem = checkField(*field, message.point_step)) {
      layout.time_problem = problem->detail + "; the cloud is read without per-point times";
    } else if (!unit) {
      layout.time_problem = "field '" + field->name + "' is " + datatypeName(field->datatype) + ", not " +
                            convention.expected + "; the cloud is read without per-point times";
    } else {
      layout.time = TimeReader{FieldReader{field->offset, field->datatype, swap_bytes}, unit->scale,
                               unit->absolute ? message.stamp : 0.0};
    }
    return;
  }
}

// Finds x, y, z and the optional fields. An unusable intensity or ring field rejects the cloud too: a
// misread ring would silently corrupt the projection. An unusable time field only loses the times
// (findTimes()).
std::optional<Rejection> findLayout(const PointCloud2View& message, Layout& layout) {
  const bool swap_bytes = message.is_bigendian != hostIsBigEndian();
  FieldReader* coordinates[] = {&layout.x, &layout.y, &layout.z};
  const char* names[] = {"x", "y", "z"};
  for (int axis = 0; axis < 3; ++axis) {
    const CloudField* field = findField(message, names[axis]);
    if (field == nullptr) return Rejection{CloudProblem::missing_field, std::string("no '") + names[axis] + "' field"};
    if (!isFloatingPoint(field->datatype)) {
      return Rejection{CloudProblem::wrong_type, "field '" + field->name + "' is " + datatypeName(field->datatype) +
                                                     "; x, y and z must be float32 or float64"};
    }
    if (auto rejection = checkField(*field, message.point_step)) return rejection;
    *coordinates[axis] = FieldReader{field->offset, field->datatype, swap_bytes};
  }
  const CloudField* intensity = findField(message, "intensity");
  const CloudField* ring = findField(message, "ring");
  for (const CloudField* field : {intensity, ring}) {
    if (field == nullptr) continue;
    if (auto rejection = checkField(*field, message.point_step)) return rejection;
  }
  if (ring != nullptr && isFloatingPoint(ring->datatype)) {
    return Rejection{CloudProblem::wrong_type,
                     "field 'ring' is " + datatypeName(ring->datatype) + "; ring must be an integer type"};
  }
  if (intensity != nullptr) layout.intensity = FieldReader{intensity->offset, intensity->datatype, swap_bytes};
  if (ring != nullptr) layout.ring = FieldReader{ring->offset, ring->datatype, swap_bytes};
  findTimes(message, swap_bytes, layout);
  return std::nullopt;
}

// The data must hold every point the header promises.
std::optional<Rejection> checkExtent(const PointCloud2View& message) {
  const size_t points = static_cast<size_t>(message.width) * message.height;
  if (points == 0) return Rejection{CloudProblem::no_points, "no points (width x height is 0)"};
  const size_t row_bytes = static_cast<size_t>(message.width) * message.point_step;
  if (message.row_step < row_bytes) {
    return Rejection{CloudProblem::truncated, "row_step " + std::to_string(message.row_step) +
                                                  " is less than width x point_step (" + std::to_string(row_bytes) + ")"};
  }
  const size_t needed = static_cast<size_t>(message.row_step) * message.height;
  if (message.data_size < needed) {
    return Rejection{CloudProblem::truncated,
                     "truncated: " + std::to_string(message.data_size) + " bytes of data, " +
                         std::to_string(needed) + " needed for " + std::to_string(message.width) + " x " +
                         std::to_string(message.height) + " points"};
  }
  return std::nullopt;
}

ConvertedCloud rejected(Rejection rejection) {
  ConvertedCloud converted;
  converted.problem = rejection.problem;
  converted.detail = std::move(rejection.detail);
  return converted;
}

// In float, as the core stores it, so that a float64 beyond float's range counts as non-finite.
Vec3f readPosition(const uint8_t* point, const Layout& layout) {
  return Eigen::Vector3d(layout.x.read(point), layout.y.read(point), layout.z.read(point)).cast<float>();
}

void appendPoint(const uint8_t* point, const Vec3f& position, const Layout& layout, PointCloud& cloud) {
  cloud.points.push_back(position);
  if (layout.intensity) cloud.intensity.push_back(static_cast<float>(layout.intensity->read(point)));
  if (layout.ring) cloud.ring.push_back(ringFromValue(layout.ring->read(point)));
  if (layout.time) {
    cloud.time.push_back(static_cast<float>(layout.time->scale * layout.time->field.read(point) - layout.time->offset));
  }
}

}  // namespace

const char* describe(CloudProblem problem) {
  switch (problem) {
    case CloudProblem::none: return "usable";
    case CloudProblem::no_points: return "no points";
    case CloudProblem::missing_field: return "no x/y/z field";
    case CloudProblem::wrong_type: return "unusable field type";
    case CloudProblem::field_outside_point: return "field outside point_step";
    case CloudProblem::truncated: return "truncated data";
    case CloudProblem::no_finite_points: return "no finite points";
  }
  return "unknown";
}

bool hostIsBigEndian() {
  const uint16_t probe = 1;
  uint8_t first_byte = 0;
  std::memcpy(&first_byte, &probe, 1);
  return first_byte == 0;
}

ConvertedCloud convertPointCloud2(const PointCloud2View& message) {
  Layout layout;
  if (auto rejection = findLayout(message, layout)) return rejected(std::move(*rejection));
  if (auto rejection = checkExtent(message)) return rejected(std::move(*rejection));

  ConvertedCloud converted;
  converted.time_problem = layout.time_problem;
  PointCloud& cloud = converted.cloud;
  cloud.stamp = message.stamp;
  const size_t capacity = static_cast<size_t>(message.width) * message.height;
  cloud.points.reserve(capacity);
  if (layout.intensity) cloud.intensity.reserve(capacity);
  if (layout.ring) cloud.ring.reserve(capacity);
  if (layout.time) cloud.time.reserve(capacity);
  for (uint32_t row = 0; row < message.height; ++row) {
    const uint8_t* row_start = message.data + static_cast<size_t>(row) * message.row_step;
    for (uint32_t column = 0; column < message.width; ++column) {
      const uint8_t* point = row_start + static_cast<size_t>(column) * message.point_step;
      const Vec3f position = readPosition(point, layout);
      if (position.allFinite()) {
        appendPoint(point, position, layout, cloud);
      } else {
        ++converted.non_finite_points;
      }
    }
  }
  if (cloud.points.empty()) {
    return rejected({CloudProblem::no_finite_points, "no finite points (all " +
                                                         std::to_string(converted.non_finite_points) +
                                                         " have a NaN or infinite coordinate)"});
  }
  return converted;
}

}  // namespace elo
