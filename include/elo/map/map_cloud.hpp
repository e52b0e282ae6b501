// A map as points: what the drive's map gives (DriveMap::points()), what a map file holds
// (io/map_pcd.hpp), and what localization matches scans against (map/point_map.hpp).
#pragma once

#include <cstddef>
#include <vector>

#include "elo/types.hpp"

namespace elo {

// Points in the map's frame. A normal is a unit vector, or zero where none is known (such a point still
// serves localization's ground term, which fits its own normals).
struct MapCloud {
  std::vector<Vec3f> points;
  std::vector<float> intensity;  // empty, or one per point
  std::vector<Vec3f> normals;    // empty (none known yet: localization estimates them), or one per point

  size_t size() const { return points.size(); }
  bool hasNormals() const { return normals.size() == points.size() && !points.empty(); }
};

}  // namespace elo
