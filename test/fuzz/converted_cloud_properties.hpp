// What every PointCloud2 conversion must give, whichever way the message arrived (a ROS message, a ROS 2
// bag's CDR bytes): a usable cloud holds only finite points, each optional channel empty or one value
// per point, and accounts for every point of the message; a rejection says why.
#pragma once

#include <cstddef>

#include "elo/io/point_cloud2.hpp"
#include "fuzz_support.hpp"

namespace elo::fuzz {

inline bool emptyOrOnePerPoint(size_t channel_size, size_t points) { return channel_size == 0 || channel_size == points; }

// `message_points`: width * height of the message converted.
inline void expectConvertedOrRejected(const ConvertedCloud& converted, size_t message_points) {
  if (!converted.usable()) {
    expectProperty(!converted.detail.empty(), "a rejection says why");
    return;
  }
  const PointCloud& cloud = converted.cloud;
  expectProperty(!cloud.points.empty(), "a usable cloud has points");
  for (const Vec3f& point : cloud.points) expectProperty(point.allFinite(), "only finite points");
  expectProperty(emptyOrOnePerPoint(cloud.intensity.size(), cloud.size()), "intensity empty or one per point");
  expectProperty(emptyOrOnePerPoint(cloud.ring.size(), cloud.size()), "ring empty or one per point");
  expectProperty(emptyOrOnePerPoint(cloud.time.size(), cloud.size()), "time empty or one per point");
  expectProperty(cloud.size() + converted.non_finite_points == message_points,
                 "every point converted or counted as non-finite");
}

}  // namespace elo::fuzz
