#include "elo/io/map_pcd.hpp"

#include <pcl/PCLPointCloud2.h>

#include <algorithm>
#include <array>
#include <iostream>
#include <optional>

#include "elo/io/io_error.hpp"
#include "pcd_format.hpp"

namespace elo {
namespace {

using pcl::PCLPointField;
using Fields = std::array<PCLPointField, 3>;

// The three floating-point fields `names`, or none when the file has none of them; some but not all three
// is an error.
std::optional<Fields> findVectorFields(const std::vector<PCLPointField>& fields, const std::array<const char*, 3>& names,
                                       const std::string& path) {
  Fields found;
  int count = 0;
  for (int axis = 0; axis < 3; ++axis) {
    const std::optional<PCLPointField> field = io_detail::findField(fields, names[axis]);
    if (!field) continue;
    if (!io_detail::isFloatingPoint(field->datatype)) {
      throw IoError("'" + path + "': field '" + names[axis] + "' must be float32 or float64");
    }
    found[axis] = *field;
    ++count;
  }
  if (count == 0) return std::nullopt;
  if (count < 3) {
    throw IoError("'" + path + "' has some of " + names[0] + ", " + names[1] + ", " + names[2] + " but not all three");
  }
  return found;
}

// In float, as the map stores it, so that a float64 beyond float's range counts as non-finite.
Vec3f readVector(const uint8_t* point, const Fields& fields) {
  Vec3f value;
  for (int axis = 0; axis < 3; ++axis) {
    value[axis] = static_cast<float>(io_detail::readScalar(point + fields[axis].offset, fields[axis].datatype));
  }
  return value;
}

}  // namespace

void writeMapPcd(const std::string& path, const MapCloud& map) {
  pcl::PCLPointCloud2 pcd;
  for (const char* name : {"x", "y", "z", "intensity"}) io_detail::addField(pcd, name, PCLPointField::FLOAT32, sizeof(float));
  const bool has_normals = map.hasNormals();
  if (has_normals) {
    for (const char* name : {"normal_x", "normal_y", "normal_z"}) {
      io_detail::addField(pcd, name, PCLPointField::FLOAT32, sizeof(float));
    }
  }
  pcd.width = static_cast<uint32_t>(map.size());
  pcd.height = 1;
  pcd.is_dense = std::all_of(map.points.begin(), map.points.end(), [](const Vec3f& p) { return p.allFinite(); });
  pcd.row_step = pcd.point_step * pcd.width;
  pcd.data.resize(static_cast<size_t>(pcd.row_step));
  for (size_t i = 0; i < map.size(); ++i) {
    uint8_t* point = pcd.data.data() + i * pcd.point_step;
    for (int axis = 0; axis < 3; ++axis) io_detail::writeScalar(point, pcd.fields[axis], map.points[i][axis]);
    io_detail::writeScalar(point, pcd.fields[3], i < map.intensity.size() ? map.intensity[i] : 0.0f);
    if (has_normals) {
      for (int axis = 0; axis < 3; ++axis) io_detail::writeScalar(point, pcd.fields[4 + axis], map.normals[i][axis]);
    }
  }
  io_detail::savePcd(path, pcd);
}

MapCloud readMapPcd(const std::string& path, size_t* non_finite_skipped) {
  const io_detail::PcdPoints pcd = io_detail::parsePcd(io_detail::readFileBytes(path), path);
  const std::optional<Fields> position = findVectorFields(pcd.fields, {"x", "y", "z"}, path);
  if (!position) throw IoError("'" + path + "' needs float32 or float64 fields x, y, z");
  const std::optional<Fields> normal = findVectorFields(pcd.fields, {"normal_x", "normal_y", "normal_z"}, path);
  const std::optional<PCLPointField> intensity = io_detail::findField(pcd.fields, "intensity");
  MapCloud map;
  map.points.reserve(pcd.count);
  size_t skipped = 0;
  for (size_t i = 0; i < pcd.count; ++i) {
    const uint8_t* point = pcd.data.data() + i * pcd.point_step;
    const Vec3f coordinates = readVector(point, *position);
    if (!coordinates.allFinite()) {
      ++skipped;
      continue;
    }
    map.points.push_back(coordinates);
    if (intensity) {
      map.intensity.push_back(static_cast<float>(io_detail::readScalar(point + intensity->offset, intensity->datatype)));
    }
    if (normal) map.normals.push_back(readVector(point, *normal));
  }
  if (non_finite_skipped != nullptr) {
    *non_finite_skipped = skipped;
  } else if (skipped > 0) {
    std::cerr << "warning: skipped " << skipped << " points with non-finite coordinates in '" << path << "'\n";
  }
  return map;
}

PreparedMap readPreparedMap(const std::string& path, double normal_radius) {
  size_t non_finite_skipped = 0;
  MapCloud map = readMapPcd(path, &non_finite_skipped);
  MapPreparation preparation = prepareMap(map, normal_radius);
  preparation.non_finite_dropped += non_finite_skipped;  // the reader's skips: prepareMap() found none left
  return {std::make_shared<const MapCloud>(std::move(map)), preparation};
}

}  // namespace elo
