// A saved map made ready for localization (a MapCloud in the map frame, its normals estimated at load
// when the file had none), and the tile index that finds the points within sensor range of a position,
// so that a map match renders only those.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <unordered_map>
#include <vector>

#include "elo/map/map_cloud.hpp"

namespace elo {

// What cleaning a loaded map did: points dropped for a non-finite coordinate (readMapPcd() skips them
// before prepareMap() sees them: the loaders add its count here), normals that were not unit vectors and
// were set to zero, normals estimated because the file had none.
struct MapPreparation {
  size_t non_finite_dropped = 0;
  size_t bad_normals = 0;
  size_t normals_estimated = 0;  // of the points, those that got a normal (the rest: too few neighbours)
  bool estimated = false;
};

// Drops non-finite points, zeroes normals that are not unit vectors, and estimates the normals when the
// map has none: each point's from the plane through its neighbours within `normal_radius` (at least 5 of
// them, and planar: the smallest eigenvalue under a tenth of the sum). Done once, at load.
MapPreparation prepareMap(MapCloud& map, double normal_radius);

// The normal of every point from its neighbours within `radius` (zero where they give no plane). Its sign
// is arbitrary: each render turns the normals towards the sensor, as the scan's face it.
void estimateMapNormals(MapCloud& map, double radius);

// Square tiles of the map's x-y plane, `tile_size` wide, each listing its points.
class MapTiles {
 public:
  // A tile's place in the grid: its column (along x) and row (along y).
  struct Cell {
    int64_t col;
    int64_t row;
  };

  MapTiles(const MapCloud& map, double tile_size);

  // The points within `radius` (in x-y) of `center`, appended to `out` in tile order.
  void pointsNear(const Eigen::Vector3d& center, double radius, std::vector<int32_t>& out) const;
  size_t tileCount() const { return tiles_.size(); }
  // The tile `point` lies in, and the points of the tile at `cell` (null when none lies there).
  Cell cellOf(const Vec3f& point) const;
  const std::vector<int32_t>* pointsIn(const Cell& cell) const;
  // The map's extent in x-y: its lower and upper corners (zero for an empty map).
  Eigen::Vector2d lower() const { return lower_; }
  Eigen::Vector2d upper() const { return upper_; }

 private:
  static uint64_t key(const Cell& cell);
  const MapCloud& map_;
  double tile_size_;
  std::unordered_map<uint64_t, std::vector<int32_t>> tiles_;
  Eigen::Vector2d lower_ = Eigen::Vector2d::Zero();
  Eigen::Vector2d upper_ = Eigen::Vector2d::Zero();
};

}  // namespace elo
