// Which of a saved map's points a device backend holds (the CUDA backend's renderMap()): not the whole
// map, whose size grows with the drive, but the tiles holding the points a render draws and the ring of
// tiles around them, so that the device's memory is bounded by the sensor's reach and not by the map's
// extent. While the vehicle stays within a tile of where that set was chosen, every render finds its
// points held; a render that needs a tile not held chooses a new set around itself, which the backend
// copies up. CUDA-free, so that it is tested where no GPU is.
#pragma once

#include <cstdint>
#include <vector>

#include "elo/map/point_map.hpp"

namespace elo {

class MapResidency {
 public:
  // The map's tiles, `tile_size` wide (localization.tile_size); none held yet.
  MapResidency(const MapCloud& map, double tile_size);

  // Where each of `points` (indices into the map) lies in the held set, written to `slots` (room for as
  // many as `points`); false when some point is not held (`slots` is then partly written).
  bool locate(const std::vector<int32_t>& points, int32_t* slots) const;

  // Holds the tiles of `points` and every tile next to one of them, in place of what was held.
  void holdAround(const std::vector<int32_t>& points);
  // Holds nothing (the backend's copy of the held set failed).
  void release();

  // The held map points in their order on the device: slot k holds point held()[k].
  const std::vector<int32_t>& held() const { return held_; }

 private:
  const MapCloud& map_;
  MapTiles tiles_;
  std::vector<int32_t> slot_of_point_;  // -1: not held
  std::vector<int32_t> held_;
};

}  // namespace elo
