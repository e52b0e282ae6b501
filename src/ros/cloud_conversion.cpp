#include "cloud_conversion.hpp"

#include <sensor_msgs/PointField.h>

#include <algorithm>
#include <cstring>

namespace elo_ros {
namespace {

using sensor_msgs::PointField;

template <typename T>
void writeField(uint8_t* point, const PointField& field, T value) {
  std::memcpy(point + field.offset, &value, sizeof(T));
}

}  // namespace

void addField(sensor_msgs::PointCloud2& message, const char* name, uint8_t datatype) {
  const uint32_t size = datatype == PointField::UINT16 ? 2 : 4;
  PointField field;
  field.name = name;
  field.datatype = datatype;
  field.count = 1;
  field.offset = (message.point_step + size - 1) / size * size;
  message.fields.push_back(field);
  message.point_step = field.offset + size;
}

elo::PointCloud2View viewOf(const sensor_msgs::PointCloud2& message) {
  elo::PointCloud2View view;
  view.stamp = message.header.stamp.toSec();
  view.height = message.height;
  view.width = message.width;
  view.fields.reserve(message.fields.size());
  for (const PointField& field : message.fields) {
    view.fields.push_back({field.name, field.offset, field.datatype, field.count});
  }
  view.is_bigendian = message.is_bigendian;
  view.point_step = message.point_step;
  view.row_step = message.row_step;
  view.data = message.data.data();
  view.data_size = message.data.size();
  return view;
}

ConvertedCloud fromPointCloud2(const sensor_msgs::PointCloud2& message) {
  return elo::convertPointCloud2(viewOf(message));
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
  message.is_bigendian = elo::hostIsBigEndian();
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
