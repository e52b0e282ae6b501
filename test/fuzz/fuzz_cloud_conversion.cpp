// PointCloud2 -> elo::PointCloud on messages built from arbitrary bytes, so that malformed layouts are
// explored: fields past point_step, unknown datatypes, short data, odd or zero steps, either byte order.
// A message is either converted or rejected with a reason, never a crash; a converted cloud holds only
// finite points, each optional channel empty or one value per point, and accounts for every point.
//
// Input layout (little-endian; a short input reads as zeros):
//   u32 width, u32 height, u32 point_step, u32 row_step, u8 is_bigendian, u8 field count (mod 8),
//   per field: u8 name (index into kFieldNames), u32 offset, u8 datatype, u32 count;
//   the remaining bytes are the data.
#include <sensor_msgs/PointCloud2.h>

#include <algorithm>
#include <cstring>

#include "cloud_conversion.hpp"
#include "converted_cloud_properties.hpp"

namespace {

// The names the conversion looks for, and one it must ignore.
const char* const kFieldNames[] = {"x", "y", "z", "intensity", "ring", "time", "t", "reflectivity"};
constexpr size_t kFieldNameCount = sizeof(kFieldNames) / sizeof(kFieldNames[0]);
constexpr uint8_t kMaxFields = 8;

class ByteReader {
 public:
  ByteReader(const uint8_t* data, size_t size) : data_(data), size_(size) {}

  template <typename T>
  T take() {
    T value{};
    const size_t available = std::min(sizeof(T), size_ - used_);
    std::memcpy(&value, data_ + used_, available);
    used_ += available;
    return value;
  }

  std::vector<uint8_t> rest() { return std::vector<uint8_t>(data_ + used_, data_ + size_); }

 private:
  const uint8_t* data_;
  size_t size_;
  size_t used_ = 0;
};

sensor_msgs::PointField takeField(ByteReader& bytes) {
  sensor_msgs::PointField field;
  field.name = kFieldNames[bytes.take<uint8_t>() % kFieldNameCount];
  field.offset = bytes.take<uint32_t>();
  field.datatype = bytes.take<uint8_t>();
  field.count = bytes.take<uint32_t>();
  return field;
}

sensor_msgs::PointCloud2 takeMessage(ByteReader& bytes) {
  sensor_msgs::PointCloud2 message;
  message.header.frame_id = "lidar";
  message.width = bytes.take<uint32_t>();
  message.height = bytes.take<uint32_t>();
  message.point_step = bytes.take<uint32_t>();
  message.row_step = bytes.take<uint32_t>();
  message.is_bigendian = bytes.take<uint8_t>() & 1;
  const uint8_t field_count = bytes.take<uint8_t>() % kMaxFields;
  for (uint8_t i = 0; i < field_count; ++i) {
    message.fields.push_back(takeField(bytes));
  }
  message.data = bytes.rest();
  return message;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  ByteReader bytes(data, size);
  const sensor_msgs::PointCloud2 message = takeMessage(bytes);
  elo::fuzz::expectConvertedOrRejected(elo_ros::fromPointCloud2(message),
                                       static_cast<size_t>(message.width) * message.height);
  return 0;
}
