// The drive's map as a PCD file (docs/map.md): binary, float32 fields x y z intensity normal_x normal_y
// normal_z, one point per map voxel, in the odometry frame (elo_run: the first scan's sensor frame; the
// node: its odom frame). A normal of (0, 0, 0) means none is known. Localization and viewers (pcl_viewer,
// CloudCompare) read it as it is.
#pragma once

#include <string>

#include "elo/drive_map.hpp"

namespace elo {

// Throws IoError when the file cannot be written.
void writeMapPcd(const std::string& path, const MapCloud& map);

// Reads a map file: x y z (float32 or float64) are required; intensity and the normal are read when
// present (else 0). A malformed file throws IoError naming it; points with a non-finite coordinate are
// skipped and counted into `non_finite_skipped` when given.
MapCloud readMapPcd(const std::string& path, size_t* non_finite_skipped = nullptr);

}  // namespace elo
