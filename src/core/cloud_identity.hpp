// Which cloud a prefetched upload holds (Backend::prefetch()): the memory of its point, ring and time
// arrays, their lengths and its stamp. A cloud moved to another PointCloud keeps its arrays' memory and
// so its identity; a copy, a cloud whose arrays were reallocated or restamped, or another cloud does not.
// Only identity is compared, never the values: a caller must not change a prefetched cloud in place.
#pragma once

#include <cstddef>

#include "elo/types.hpp"

namespace elo {

struct CloudIdentity {
  const void* points = nullptr;
  size_t point_count = 0;
  const void* rings = nullptr;
  size_t ring_count = 0;
  const void* times = nullptr;
  size_t time_count = 0;
  double stamp = 0.0;

  static CloudIdentity of(const PointCloud& cloud) {
    return {cloud.points.data(), cloud.points.size(), cloud.ring.data(), cloud.ring.size(),
            cloud.time.data(),   cloud.time.size(),   cloud.stamp};
  }

  // A stamp that is not a number matches nothing: such a scan is never processed anyway.
  bool operator==(const CloudIdentity& other) const {
    return points == other.points && point_count == other.point_count && rings == other.rings &&
           ring_count == other.ring_count && times == other.times && time_count == other.time_count &&
           stamp == other.stamp;
  }
};

}  // namespace elo
