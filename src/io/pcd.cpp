#include "elo/io/pcd.hpp"

#include <pcl/PCLPointCloud2.h>
#include <pcl/io/pcd_io.h>

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <optional>

#include "elo/io/io_error.hpp"
#include "pcd_format.hpp"
#include "text_format.hpp"

namespace elo {
namespace io_detail {

using pcl::PCLPointField;

std::optional<PCLPointField> findField(const std::vector<PCLPointField>& fields, const std::string& name) {
  for (const PCLPointField& field : fields) {
    if (field.name == name) {
      return field;
    }
  }
  return std::nullopt;
}

template <typename T>
double readAs(const uint8_t* bytes) {
  T value;
  std::memcpy(&value, bytes, sizeof(T));
  return static_cast<double>(value);
}

// Any PCD scalar as a double; PCD data need not be aligned, hence the memcpy in readAs.
double readScalar(const uint8_t* bytes, uint8_t datatype) {
  switch (datatype) {
    case PCLPointField::INT8: return readAs<int8_t>(bytes);
    case PCLPointField::UINT8: return readAs<uint8_t>(bytes);
    case PCLPointField::INT16: return readAs<int16_t>(bytes);
    case PCLPointField::UINT16: return readAs<uint16_t>(bytes);
    case PCLPointField::INT32: return readAs<int32_t>(bytes);
    case PCLPointField::UINT32: return readAs<uint32_t>(bytes);
    case io_detail::kPcdInt64: return readAs<int64_t>(bytes);
    case io_detail::kPcdUint64: return readAs<uint64_t>(bytes);
    case PCLPointField::FLOAT32: return readAs<float>(bytes);
    case PCLPointField::FLOAT64: return readAs<double>(bytes);
    default: return readAs<uint8_t>(bytes);  // BOOL: one byte
  }
}

bool isFloatingPoint(uint8_t datatype) {
  return datatype == PCLPointField::FLOAT32 || datatype == PCLPointField::FLOAT64;
}

void addField(pcl::PCLPointCloud2& cloud, const std::string& name, uint8_t datatype, uint32_t size) {
  PCLPointField field;
  field.name = name;
  field.offset = cloud.point_step;
  field.datatype = datatype;
  field.count = 1;
  cloud.fields.push_back(field);
  cloud.point_step += size;
}

// The whole file in one read: a scan is a few MB, and the parser checks its sizes against it.
std::string readFileBytes(const std::string& path) {
  if (!std::filesystem::is_regular_file(path)) {
    throw IoError("cannot read '" + path + "': no such file");
  }
  std::ifstream stream = io_detail::openForReading(path, std::ios::binary);
  std::error_code error;
  const auto size = static_cast<size_t>(std::filesystem::file_size(path, error));
  if (error) {
    throw IoError("cannot read the size of '" + path + "': " + error.message());
  }
  std::string bytes(size, '\0');
  if (!stream.read(bytes.data(), static_cast<std::streamsize>(size))) {
    throw IoError("reading '" + path + "' failed after " + std::to_string(stream.gcount()) + " bytes");
  }
  return bytes;
}

void savePcd(const std::string& path, const pcl::PCLPointCloud2& cloud) {
  if (cloud.width * cloud.height == 0) {
    // PCL 1.11 (Debian 11) refuses to write a cloud without points; PCL 1.13 writes its header and an
    // empty binary DATA section, as this does for every PCL (docs/platforms.md).
    std::ofstream stream = openForWriting(path, std::ios::binary);
    stream << pcl::PCDWriter().generateHeaderBinary(cloud, Eigen::Vector4f::Zero(), Eigen::Quaternionf::Identity())
           << "DATA binary\n";
    finishWriting(stream, path);
    return;
  }
  if (pcl::io::savePCDFile(path, cloud, Eigen::Vector4f::Zero(), Eigen::Quaternionf::Identity(), true) != 0) {
    throw IoError("cannot write '" + path + "'");
  }
}

}  // namespace io_detail
namespace {

using pcl::PCLPointField;
using io_detail::findField;
using io_detail::isFloatingPoint;
using io_detail::readScalar;
using io_detail::addField;
using io_detail::writeScalar;

// The fields of a PCD scan that a PointCloud holds, checked once so that the per-point loop only reads.
struct FieldLayout {
  PCLPointField x, y, z;
  std::optional<PCLPointField> intensity, ring, time;
  double time_scale = 1.0;  // seconds per stored unit
};

FieldLayout findLayout(const std::vector<PCLPointField>& fields, const std::string& path) {
  FieldLayout layout;
  PCLPointField* coordinates[] = {&layout.x, &layout.y, &layout.z};
  const char* names[] = {"x", "y", "z"};
  for (int axis = 0; axis < 3; ++axis) {
    const std::optional<PCLPointField> field = findField(fields, names[axis]);
    if (!field || !isFloatingPoint(field->datatype)) {
      throw IoError("'" + path + "' needs a float32 or float64 field '" + names[axis] + "'");
    }
    *coordinates[axis] = *field;
  }
  layout.intensity = findField(fields, "intensity");
  layout.ring = findField(fields, "ring");
  if (layout.ring && isFloatingPoint(layout.ring->datatype)) {
    throw IoError("'" + path + "': field 'ring' must be an integer type");
  }
  layout.time = findField(fields, "time");
  if (!layout.time) {
    layout.time = findField(fields, "t");
  }
  if (layout.time && !isFloatingPoint(layout.time->datatype)) {
    layout.time_scale = 1e-9;  // integer times are nanoseconds (Ouster)
  }
  return layout;
}

// In float, as the cloud stores it, so that a float64 beyond float's range counts as non-finite.
Vec3f readPosition(const uint8_t* point, const FieldLayout& layout) {
  return Eigen::Vector3d(readScalar(point + layout.x.offset, layout.x.datatype),
                         readScalar(point + layout.y.offset, layout.y.datatype),
                         readScalar(point + layout.z.offset, layout.z.datatype))
      .cast<float>();
}

void appendPoint(const uint8_t* point, const Vec3f& position, const FieldLayout& layout, PointCloud& cloud) {
  cloud.points.push_back(position);
  if (layout.intensity) {
    cloud.intensity.push_back(
        static_cast<float>(readScalar(point + layout.intensity->offset, layout.intensity->datatype)));
  }
  if (layout.ring) {
    cloud.ring.push_back(ringFromValue(readScalar(point + layout.ring->offset, layout.ring->datatype)));
  }
  if (layout.time) {
    cloud.time.push_back(static_cast<float>(
        layout.time_scale * readScalar(point + layout.time->offset, layout.time->datatype)));
  }
}

}  // namespace

PointCloud readPcd(const std::string& path, size_t* non_finite_skipped) {
  const io_detail::PcdPoints pcd = io_detail::parsePcd(io_detail::readFileBytes(path), path);
  const FieldLayout layout = findLayout(pcd.fields, path);
  PointCloud cloud;
  size_t skipped = 0;
  for (size_t i = 0; i < pcd.count; ++i) {
    const uint8_t* point = pcd.data.data() + i * pcd.point_step;
    const Vec3f position = readPosition(point, layout);
    if (position.allFinite()) {
      appendPoint(point, position, layout, cloud);
    } else {
      ++skipped;  // organised clouds mark missing returns with NaN
    }
  }
  if (non_finite_skipped != nullptr) {
    *non_finite_skipped = skipped;
  } else if (skipped > 0) {
    std::cerr << "warning: skipped " << skipped << " points with non-finite coordinates in '" << path << "'\n";
  }
  return cloud;
}

void writePcd(const std::string& path, const PointCloud& cloud) {
  pcl::PCLPointCloud2 pcd;
  addField(pcd, "x", PCLPointField::FLOAT32, 4);
  addField(pcd, "y", PCLPointField::FLOAT32, 4);
  addField(pcd, "z", PCLPointField::FLOAT32, 4);
  addField(pcd, "intensity", PCLPointField::FLOAT32, 4);
  const bool has_ring = !cloud.ring.empty();
  const bool has_time = !cloud.time.empty();
  if (has_ring) addField(pcd, "ring", PCLPointField::UINT16, 2);
  if (has_time) addField(pcd, "time", PCLPointField::FLOAT32, 4);
  pcd.width = static_cast<uint32_t>(cloud.size());
  pcd.height = 1;
  pcd.is_dense = std::all_of(cloud.points.begin(), cloud.points.end(), [](const Vec3f& p) { return p.allFinite(); });
  pcd.row_step = pcd.point_step * pcd.width;
  pcd.data.resize(static_cast<size_t>(pcd.row_step));
  for (size_t i = 0; i < cloud.size(); ++i) {
    uint8_t* point = pcd.data.data() + i * pcd.point_step;
    writeScalar(point, pcd.fields[0], cloud.points[i].x());
    writeScalar(point, pcd.fields[1], cloud.points[i].y());
    writeScalar(point, pcd.fields[2], cloud.points[i].z());
    writeScalar(point, pcd.fields[3], cloud.intensity.empty() ? 0.0f : cloud.intensity[i]);
    if (has_ring) writeScalar(point, pcd.fields[4], cloud.ring[i]);
    if (has_time) writeScalar(point, pcd.fields.back(), cloud.time[i]);
  }
  io_detail::savePcd(path, pcd);
}

}  // namespace elo
