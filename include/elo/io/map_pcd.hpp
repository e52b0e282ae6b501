// A map as a PCD file (docs/map.md, docs/localization.md): written binary, float32 fields x y z
// intensity, and normal_x normal_y normal_z when the map has normals (the drive's map always does: a
// normal of (0, 0, 0) means none is known). The drive's map is saved with it, localization loads its map
// with it, and viewers (pcl_viewer, CloudCompare) read it as it is.
#pragma once

#include <cstddef>
#include <memory>
#include <string>

#include "elo/map/point_map.hpp"
#include "elo/map/map_cloud.hpp"

namespace elo {

// Throws IoError when the file cannot be written. Intensity is written as 0 where the map has none.
void writeMapPcd(const std::string& path, const MapCloud& map);

// Reads a map file: x y z (float32 or float64) are required; `intensity` (any numeric type) is read when
// present (else left empty), and the normal when all three of normal_x normal_y normal_z (floating
// point) are (else left empty: MapCloud::hasNormals() is false). Normals are read as they are:
// prepareMap() zeroes and counts those that are not unit vectors. A malformed file, or one with some
// normal fields but not all three, throws IoError naming it. Points with a non-finite coordinate are
// skipped and counted into `non_finite_skipped`; when that is null and points were skipped, a warning
// naming the file goes to stderr, so a skip is never silent.
MapCloud readMapPcd(const std::string& path, size_t* non_finite_skipped = nullptr);

// A map to localize in (elo_run --localize, the node's ~localization_map): read, then prepared
// (prepareMap(): normals estimated within `normal_radius` where it has none). `preparation` says what
// that did, the points the reader skipped counted among the non-finite ones dropped.
struct PreparedMap {
  std::shared_ptr<const MapCloud> cloud;
  MapPreparation preparation;
};
PreparedMap readPreparedMap(const std::string& path, double normal_radius);

}  // namespace elo
