#include "cloud_conversion.hpp"

#include <sensor_msgs/PointField.h>

#include <algorithm>
#include <cstring>
#include <optional>

namespace elo_ros {
namespace {

using sensor_msgs::PointField;

size_t datatypeSize(uint8_t datatype) {
  switch (datatype) {
    case PointField::INT8:
    case PointField::UINT8: return 1;
    case PointField::INT16:
    case PointField::UINT16: return 2;
    case PointField::INT32:
    case PointField::UINT32:
    case PointField::FLOAT32: return 4;
    case PointField::FLOAT64: return 8;
    default: return 0;  // not a PointField type
  }
}

std::string datatypeName(uint8_t datatype) {
  switch (datatype) {
    case PointField::INT8: return "int8";
    case PointField::UINT8: return "uint8";
    case PointField::INT16: return "int16";
    case PointField::UINT16: return "uint16";
    case PointField::INT32: return "int32";
    case PointField::UINT32: return "uint32";
    case PointField::FLOAT32: return "float32";
    case PointField::FLOAT64: return "float64";
    default: return "unknown datatype " + std::to_string(datatype);
  }
}

bool isFloatingPoint(uint8_t datatype) {
  return datatype == PointField::FLOAT32 || datatype == PointField::FLOAT64;
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
      case PointField::INT8: return readAs<int8_t>(source, swap_bytes);
      case PointField::UINT8: return readAs<uint8_t>(source, swap_bytes);
      case PointField::INT16: return readAs<int16_t>(source, swap_bytes);
      case PointField::UINT16: return readAs<uint16_t>(source, swap_bytes);
      case PointField::INT32: return readAs<int32_t>(source, swap_bytes);
      case PointField::UINT32: return readAs<uint32_t>(source, swap_bytes);
      case PointField::FLOAT32: return readAs<float>(source, swap_bytes);
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

const PointField* findField(const sensor_msgs::PointCloud2& message, const std::string& name) {
  const auto field = std::find_if(message.fields.begin(), message.fields.end(),
                                  [&](const PointField& f) { return f.name == name; });
  return field == message.fields.end() ? nullptr : &*field;
}

// A field the conversion reads must have a known type and lie inside a point.
std::optional<Rejection> checkField(const PointField& field, uint32_t point_step) {
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

// The drivers' per-point time conventions (docs/deskew.md), in this order of preference:
//   `time`      float32/float64 s relative to the header stamp (Velodyne: negative, the stamp ends the sweep)
//   `t`         uint32/int32 ns from the sweep's start, which the header stamp is (Ouster)
//   `timestamp` float64 absolute s (Hesai, RoboSense): the header stamp is subtracted
// A time field of another type cannot hold a sweep's times (an 8- or 16-bit count of nanoseconds, an
// absolute time in float32, to two minutes): the cloud is read without times and `time_problem` says
// why, so that the scan is still used, as an instantaneous one.
void findTimes(const sensor_msgs::PointCloud2& message, bool swap_bytes, Layout& layout) {
  struct Convention {
    const char* name;
    bool (*accepts)(uint8_t datatype);
    double scale;
    bool absolute;
    const char* expected;
  };
  static const Convention kConventions[] = {
      {"time", isFloatingPoint, 1.0, false, "float32 or float64 seconds relative to the header stamp"},
      {"t", [](uint8_t type) { return type == PointField::UINT32 || type == PointField::INT32; }, 1e-9, false,
       "uint32 nanoseconds from the header stamp"},
      {"timestamp", [](uint8_t type) { return type == PointField::FLOAT64; }, 1.0, true, "float64 absolute seconds"},
  };
  for (const Convention& convention : kConventions) {
    const PointField* field = findField(message, convention.name);
    if (field == nullptr) continue;
    if (auto problem = checkField(*field, message.point_step)) {
      layout.time_problem = problem->detail + "; the cloud is read without per-point times";
    } else if (!convention.accepts(field->datatype)) {
      layout.time_problem = "field '" + field->name + "' is " + datatypeName(field->datatype) + ", not " +
                            convention.expected + "; the cloud is read without per-point times";
    } else {
      layout.time = TimeReader{FieldReader{field->offset, field->datatype, swap_bytes}, convention.scale,
                               convention.absolute ? message.header.stamp.toSec() : 0.0};
    }
    return;
  }
}

// Finds x, y, z and the optional fields. An unusable intensity or ring field rejects the cloud too: a
// misread ring would silently corrupt the projection. An unusable time field only loses the times
// (findTimes()).
std::optional<Rejection> findLayout(const sensor_msgs::PointCloud2& message, Layout& layout) {
  const bool swap_bytes = message.is_bigendian != hostIsBigEndian();
  FieldReader* coordinates[] = {&layout.x, &layout.y, &layout.z};
  const char* names[] = {"x", "y", "z"};
  for (int axis = 0; axis < 3; ++axis) {
    const PointField* field = findField(message, names[axis]);
    if (field == nullptr) return Rejection{CloudProblem::missing_field, std::string("no '") + names[axis] + "' field"};
    if (!isFloatingPoint(field->datatype)) {
      return Rejection{CloudProblem::wrong_type, "field '" + field->name + "' is " + datatypeName(field->datatype) +
                                                     "; x, y and z must be float32 or float64"};
    }
    if (auto rejection = checkField(*field, message.point_step)) return rejection;
    *coordinates[axis] = FieldReader{field->offset, field->datatype, swap_bytes};
  }
  const PointField* intensity = findField(message, "intensity");
  const PointField* ring = findField(message, "ring");
  for (const PointField* field : {intensity, ring}) {
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
std::optional<Rejection> checkExtent(const sensor_msgs::PointCloud2& message) {
  const size_t points = static_cast<size_t>(message.width) * message.height;
  if (points == 0) return Rejection{CloudProblem::no_points, "no points (width x height is 0)"};
  const size_t row_bytes = static_cast<size_t>(message.width) * message.point_step;
  if (message.row_step < row_bytes) {
    return Rejection{CloudProblem::truncated, "row_step " + std::to_string(message.row_step) +
                                                  " is less than width x point_step (" + std::to_string(row_bytes) + ")"};
  }
  const size_t needed = static_cast<size_t>(message.row_step) * message.height;
  if (message.data.size() < needed) {
    return Rejection{CloudProblem::truncated,
                     "truncated: " + std::to_string(message.data.size()) + " bytes of data, " +
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
elo::Vec3f readPosition(const uint8_t* point, const Layout& layout) {
  return Eigen::Vector3d(layout.x.read(point), layout.y.read(point), layout.z.read(point)).cast<float>();
}

void appendPoint(const uint8_t* point, const elo::Vec3f& position, const Layout& layout, elo::PointCloud& cloud) {
  cloud.points.push_back(position);
  if (layout.intensity) cloud.intensity.push_back(static_cast<float>(layout.intensity->read(point)));
  if (layout.ring) cloud.ring.push_back(elo::ringFromValue(layout.ring->read(point)));
  if (layout.time) {
    cloud.time.push_back(static_cast<float>(layout.time->scale * layout.time->field.read(point) - layout.time->offset));
  }
}

// Appends a float32 or uint16 field at the next offset aligned to its size, as a C struct would.
void addField(sensor_msgs::PointCloud2& message, const char* name, uint8_t datatype) {
  const uint32_t size = static_cast<uint32_t>(datatypeSize(datatype));
  PointField field;
  field.name = name;
  field.datatype = datatype;
  field.count = 1;
  field.offset = (message.point_step + size - 1) / size * size;
  message.fields.push_back(field);
  message.point_step = field.offset + size;
}

template <typename T>
void writeField(uint8_t* point, const PointField& field, T value) {
  std::memcpy(point + field.offset, &value, sizeof(T));
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

ConvertedCloud fromPointCloud2(const sensor_msgs::PointCloud2& message) {
  Layout layout;
  if (auto rejection = findLayout(message, layout)) return rejected(std::move(*rejection));
  if (auto rejection = checkExtent(message)) return rejected(std::move(*rejection));

  ConvertedCloud converted;
  converted.time_problem = layout.time_problem;
  elo::PointCloud& cloud = converted.cloud;
  cloud.stamp = message.header.stamp.toSec();
  const size_t capacity = static_cast<size_t>(message.width) * message.height;
  cloud.points.reserve(capacity);
  if (layout.intensity) cloud.intensity.reserve(capacity);
  if (layout.ring) cloud.ring.reserve(capacity);
  if (layout.time) cloud.time.reserve(capacity);
  for (uint32_t row = 0; row < message.height; ++row) {
    const uint8_t* row_start = message.data.data() + static_cast<size_t>(row) * message.row_step;
    for (uint32_t column = 0; column < message.width; ++column) {
      const uint8_t* point = row_start + static_cast<size_t>(column) * message.point_step;
      const elo::Vec3f position = readPosition(point, layout);
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

sensor_msgs::PointCloud2 toPointCloud2(const elo::PointCloud& cloud, const std::string& frame_id) {
  sensor_msgs::PointCloud2 message;
  message.header.stamp.fromSec(cloud.stamp);
  message.header.frame_id = frame_id;
  const bool has_intensity = !cloud.intensity.empty();
  const bool has_ring = !cloud.ring.empty();
  const bool has_time = !cloud.time.empty();
  for (const char* axis : {"x", "y", "z"}) addField(message, axis, PointField::FLOAT32);
  if (has_intensity) addField(message, "intensity", PointField::FLOAT32);
  if (has_ring) addField(message, "ring", PointField::UINT16);
  if (has_time) addField(message, "time", PointField::FLOAT32);
  message.point_step = (message.point_step + 3) / 4 * 4;  // consecutive points stay 4-byte aligned
  message.height = 1;
  message.width = static_cast<uint32_t>(cloud.size());
  message.row_step = message.point_step * message.width;
  message.is_bigendian = hostIsBigEndian();
  message.is_dense =
      std::all_of(cloud.points.begin(), cloud.points.end(), [](const elo::Vec3f& p) { return p.allFinite(); });
  message.data.resize(message.row_step);
  for (size_t i = 0; i < cloud.size(); ++i) {
    uint8_t* point = message.data.data() + i * message.point_step;
    size_t field = 0;
    for (int axis = 0; axis < 3; ++axis) writeField(point, message.fields[field++], cloud.points[i][axis]);
    if (has_intensity) writeField(point, message.fields[field++], cloud.intensity[i]);
    if (has_ring) writeField(point, message.fields[field++], cloud.ring[i]);
    if (has_time) writeField(point, message.fields[field++], cloud.time[i]);
  }
  return message;
}

}  // namespace elo_ros
