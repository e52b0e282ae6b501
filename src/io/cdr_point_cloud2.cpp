#include "elo/io/cdr_point_cloud2.hpp"

#include <string>

#include "cdr_reader.hpp"

namespace elo {
namespace {

using io_detail::CdrReader;

constexpr char kMessageType[] = "PointCloud2";

CloudField readField(CdrReader& reader) {
  CloudField field;
  field.name = reader.readString("fields[].name");
  field.offset = reader.read<uint32_t>("fields[].offset");
  field.datatype = reader.read<uint8_t>("fields[].datatype");
  field.count = reader.read<uint32_t>("fields[].count");
  return field;
}

}  // namespace

double decodeCdrStamp(const uint8_t* data, size_t size) {
  CdrReader reader(data, size, kMessageType);
  return reader.readStamp();
}

PointCloud2View decodeCdrPointCloud2(const uint8_t* data, size_t size) {
  constexpr size_t kMinFieldBytes = 13;  // name length, offset, datatype, count
  CdrReader reader(data, size, kMessageType);
  PointCloud2View view;
  view.stamp = reader.readStamp();
  reader.readString("header.frame_id");
  view.height = reader.read<uint32_t>("height");
  view.width = reader.read<uint32_t>("width");
  const uint32_t field_count = reader.readCount(kMinFieldBytes, "fields");
  view.fields.reserve(field_count);
  for (uint32_t i = 0; i < field_count; ++i) view.fields.push_back(readField(reader));
  view.is_bigendian = reader.readBool("is_bigendian");
  view.point_step = reader.read<uint32_t>("point_step");
  view.row_step = reader.read<uint32_t>("row_step");
  view.data_size = reader.readCount(1, "data");
  view.data = reader.readBytes(view.data_size, "data");
  reader.readBool("is_dense");
  return view;
}

}  // namespace elo
