// The PCD file format (ascii, binary and binary_compressed), parsed here rather than by PCL's reader
// (not installed). PCL 1.13 trusts the header: a SIZE that contradicts TYPE makes it write past its
// buffer, a header line with fewer values than FIELDS throws std::out_of_range, and a large POINTS
// allocates before anything is checked. This parser checks every size against the file first, and a
// malformed file is an IoError naming the file and the line.
#pragma once

#include <pcl/PCLPointCloud2.h>
#include <pcl/PCLPointField.h>
#include <pcl/pcl_config.h>

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <optional>
#include <string>
#include <vector>

namespace elo::io_detail {

// The datatypes of 64-bit integer fields. PCL names them from 1.13 (PCLPointField::INT64, UINT64); older
// PCL (1.10 on Noetic, 1.12 on Ubuntu 22.04) has no such datatype, and the fields of a parsed PCD live
// only in this reader's PcdPoints, so it names them itself, with the numbers PCL 1.13 gives them.
#if PCL_VERSION_COMPARE(>=, 1, 13, 0)
constexpr uint8_t kPcdInt64 = pcl::PCLPointField::INT64;
constexpr uint8_t kPcdUint64 = pcl::PCLPointField::UINT64;
#else
constexpr uint8_t kPcdInt64 = 9;
constexpr uint8_t kPcdUint64 = 10;
#endif

struct PcdPoints {
  std::vector<pcl::PCLPointField> fields;  // offset, datatype and count of each field within a point
  size_t point_step = 0;                   // bytes per point
  size_t count = 0;                        // width x height
  std::vector<uint8_t> data;               // count x point_step bytes, each point packed as `fields` say
};

// `bytes` is the whole file, `path` its name for messages.
PcdPoints parsePcd(const std::string& bytes, const std::string& path);

// Shared by the readers and writers of scans (pcd.cpp) and maps (map_pcd.cpp), defined in pcd.cpp.
std::optional<pcl::PCLPointField> findField(const std::vector<pcl::PCLPointField>& fields, const std::string& name);
// Any PCD scalar at `bytes` (not necessarily aligned) as a double.
double readScalar(const uint8_t* bytes, uint8_t datatype);
bool isFloatingPoint(uint8_t datatype);
// Appends a one-value field of `size` bytes to the cloud's point layout.
void addField(pcl::PCLPointCloud2& cloud, const std::string& name, uint8_t datatype, uint32_t size);
// The whole file; IoError when it is missing or cannot be read.
std::string readFileBytes(const std::string& path);
// Binary PCD; IoError when it cannot be written.
void savePcd(const std::string& path, const pcl::PCLPointCloud2& cloud);
// Stores `value` into the field of the point at `point` (not necessarily aligned).
template <typename T>
void writeScalar(uint8_t* point, const pcl::PCLPointField& field, T value) {
  std::memcpy(point + field.offset, &value, sizeof(T));
}

}  // namespace elo::io_detail
