#include "elo/io/map_pcd.hpp"

#include <pcl/PCLPointCloud2.h>

#include <array>
#include <cstring>
#include <iostream>

#include "elo/io/io_error.hpp"
#include "pcd_format.hpp"

namespace elo {
namespace {

using pcl::PCLPointField;

constexpr const char* kFieldNames[] = {"x", "y", "z", "intensity", "normal_x", "normal_y", "normal_z"};
constexpr int kFields = 7;

// The seven values of map point `i`, in kFieldNames' order.
std::array<float, kFields> mapValues(const MapCloud& map, size_t i) {
  const Vec3f& point = map.points[i];
  const Vec3f normal = i < map.normals.size() ? map.normals[i] : Vec3f::Zero();
  const float intensity = i < map.intensity.size() ? map.intensity[i] : 0.0f;
  return {point.x(), point.y(), point.z(), intensity, normal.x(), normal.y(), normal.z()};
}

}  // namespace

void writeMapPcd(const std::string& path, const MapCloud& map) {
  pcl::PCLPointCloud2 pcd;
  for (const char* name : kFieldNames) io_detail::addField(pcd, name, PCLPointField::FLOAT32, sizeof(float));
  pcd.width = static_cast<uint32_t>(map.size());
  pcd.height = 1;
  pcd.is_dense = true;  // the map holds finite points only
  pcd.row_step = pcd.point_step * pcd.width;
  pcd.data.resize(static_cast<size_t>(pcd.row_step));
  for (size_t i = 0; i < map.size(); ++i) {
    const std::array<float, kFields> values = mapValues(map, i);
    std::memcpy(pcd.data.data() + i * pcd.point_step, values.data(), sizeof(values));
  }
  io_detail::savePcd(path, pcd);
}

MapCloud readMapPcd(const std::string& path, size_t* non_finite_skipped) {
  const io_detail::PcdPoints pcd = io_detail::parsePcd(io_detail::readFileBytes(path), path);
  std::array<std::optional<PCLPointField>, kFields> fields;
  for (int f = 0; f < kFields; ++f) fields[f] = io_detail::findField(pcd.fields, kFieldNames[f]);
  for (int axis = 0; axis < 3; ++axis) {
    if (!fields[axis] || !io_detail::isFloatingPoint(fields[axis]->datatype)) {
      throw IoError("'" + path + "' needs a float32 or float64 field '" + kFieldNames[axis] + "'");
    }
  }
  MapCloud map;
  size_t skipped = 0;
  for (size_t i = 0; i < pcd.count; ++i) {
    const uint8_t* point = pcd.data.data() + i * pcd.point_step;
    std::array<float, kFields> values{};
    for (int f = 0; f < kFields; ++f) {
      if (fields[f]) values[f] = static_cast<float>(io_detail::readScalar(point + fields[f]->offset, fields[f]->datatype));
    }
    const Vec3f position(values[0], values[1], values[2]);
    if (!position.allFinite()) {
      ++skipped;
      continue;
    }
    const Vec3f normal(values[4], values[5], values[6]);
    map.points.push_back(position);
    map.intensity.push_back(values[3]);
    map.normals.push_back(normal.allFinite() ? normal : Vec3f::Zero());
  }
  if (non_finite_skipped != nullptr) {
    *non_finite_skipped = skipped;
  } else if (skipped > 0) {
    std::cerr << "warning: skipped " << skipped << " points with non-finite coordinates in '" << path << "'\n";
  }
  return map;
}

}  // namespace elo
